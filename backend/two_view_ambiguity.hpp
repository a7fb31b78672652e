#pragma once
// Whether a two-view pair's correspondences determine its motion (docs/math/two_view.md,
// "Ambiguous pairs"): a homography that explains them, and the motions it allows.

#include <Eigen/Core>
#include <optional>
#include <vector>

#include "backend/relative_pose_refinement.hpp"
#include "core/pinhole_camera.hpp"

namespace parallax {

/// Correspondences of a pair of undistorted images, pixels (same order in both).
struct PixelCorrespondences {
  std::vector<Eigen::Vector2d> ref, cur;
};

/// The pixels in normalised coordinates (the ray at z = 1, PinholeCamera::Unproject).
std::vector<Eigen::Vector2d> Normalised(const PinholeCamera& camera,
                                        const std::vector<Eigen::Vector2d>& pixels);

/// Reference-to-frame homography fitted by RANSAC (`threshold_px`); nullopt when fewer than
/// 4 correspondences or the fit fails.
std::optional<Eigen::Matrix3d> FitHomography(const PixelCorrespondences& c, double threshold_px);

/// Share of the correspondences that `H` transfers to within `threshold_px` of their match.
double HomographyShare(const Eigen::Matrix3d& H, const PixelCorrespondences& c,
                       double threshold_px);

/// The motions `H` allows (its decomposition; up to two distinct ones), each polished on the
/// correspondences like the pair's pose, that differ from `pose` by more than
/// `min_rotation_deg` of rotation or `min_direction_deg` of translation direction (sign
/// ignored): the smallest ratio of such a twin's robust Sampson cost to `pose`'s, or nullopt
/// when there is no twin.
std::optional<double> TwinCostRatio(const PinholeCamera& camera, const Eigen::Matrix3d& H,
                                    const PixelCorrespondences& c, const RelativePose& pose,
                                    double min_rotation_deg = 0.5, double min_direction_deg = 5.0);

}  // namespace parallax
