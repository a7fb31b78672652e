#pragma once
// Sim(3) between two keyframes from matched points with depth (3-D to 3-D), by RANSAC over
// minimal 3-point Umeyama fits with a reprojection test in both images
// (docs/place_recognition.md, "Geometric verification").

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "core/pinhole_camera.hpp"
#include "core/sim3.hpp"

namespace parallax {

/// A feature seen in keyframes a and b, with its point in each keyframe's coordinates (from
/// that keyframe's depth) and its pixel position there; sigma: the pixel position's
/// standard deviation (the ORB octave's scale).
struct PointMatch3d {
  Eigen::Vector3d p_a;
  Eigen::Vector3d p_b;
  Eigen::Vector2d px_a;
  Eigen::Vector2d px_b;
  double sigma_a = 1.0;
  double sigma_b = 1.0;
};

struct Sim3RansacOptions {
  int max_iterations = 300;
  /// A match is an inlier when its reprojection error is below sqrt(chi2) sigma in both
  /// images (9.21: chi^2 with 2 degrees of freedom at 99%).
  double max_reprojection_chi2 = 9.21;
  int min_inliers = 20;
  /// Stop early once this confidence that an all-inlier sample was drawn is reached.
  double confidence = 0.999;
  std::uint64_t seed = 7;

  void Check() const;
};

struct Sim3RansacResult {
  bool found = false;
  Sim3d S_a_b;  ///< maps points of b into a (refitted on all inliers)
  std::vector<std::uint32_t> inliers;
  int iterations = 0;
};

/// Deterministic for given matches and options (own random generator).
Sim3RansacResult EstimateSim3Ransac(const std::vector<PointMatch3d>& matches,
                                    const PinholeCamera& camera, const Sim3RansacOptions& options);

/// Whether match m is consistent with S_a_b under the options' reprojection test.
bool IsSim3Inlier(const PointMatch3d& m, const Sim3d& S_a_b, const Sim3d& S_b_a,
                  const PinholeCamera& camera, double max_chi2);

}  // namespace parallax
