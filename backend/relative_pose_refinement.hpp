#pragma once
// Least-squares polish of a two-view relative pose on all its inliers (docs/math/two_view.md).

#include <Eigen/Core>
#include <vector>

#include "core/so3.hpp"

namespace parallax {

struct RelativePoseRefinementOptions {
  int max_iterations = 10;
  /// Huber threshold on the Sampson distance, pixels.
  double huber_px = 1.0;
  /// Stop when the update's norm (radians, rotation and direction together) is below this.
  double min_step = 1e-7;

  /// Throws std::invalid_argument naming the bad field.
  void Check() const;
};

/// Relative pose of two calibrated views: x_cur ~ R_cur_ref * x_ref + t_cur_ref, with
/// |t_cur_ref| = 1 (two views fix the translation's direction only).
struct RelativePose {
  SO3d R_cur_ref;
  Eigen::Vector3d t_cur_ref = Eigen::Vector3d::UnitZ();
};

/// Signed Sampson distance of a correspondence (normalised image coordinates, z = 1 implied)
/// under the essential matrix E = [t]x R, in normalised units (multiply by the focal length
/// for pixels): the first-order distance of the pair to the epipolar constraint x_cur^T E x_ref
/// = 0 (Hartley & Zisserman, eq. 11.9).
double SampsonDistance(const Eigen::Matrix3d& E, const Eigen::Vector2d& x_ref,
                       const Eigen::Vector2d& x_cur);

/// Mean Huber cost (threshold `huber_px`) of the Sampson distances in pixels (normalised
/// distances times `focal_px`): what RefineRelativePose minimises, per correspondence.
/// Precondition: x_ref and x_cur of equal, non-zero size.
double RelativePoseCost(const std::vector<Eigen::Vector2d>& x_ref,
                        const std::vector<Eigen::Vector2d>& x_cur, const RelativePose& pose,
                        double focal_px, double huber_px);

/// Refines `initial` by Gauss-Newton with Huber weights on the Sampson distances of the
/// correspondences (normalised coordinates; `focal_px` converts the Huber threshold). The
/// rotation is updated on the left (R <- Exp(w) R) and the unit translation on its tangent
/// plane. RANSAC's minimal 5-point model uses 5 of the inliers; this uses all of them.
/// Returns `initial` when there are fewer than 5 correspondences or the cost does not improve.
RelativePose RefineRelativePose(const std::vector<Eigen::Vector2d>& x_ref,
                                const std::vector<Eigen::Vector2d>& x_cur,
                                const RelativePose& initial, double focal_px,
                                const RelativePoseRefinementOptions& options = {});

/// Covariance of a refined pose's five parameters at `pose`: the rotation on the left
/// (radians, rows 0-2) and the unit translation on its tangent plane (rows 3-4), as
/// sigma^2 (J^T W J)^-1 with the Huber weights of RefineRelativePose and sigma^2 the weighted
/// residual variance (pixels^2). Where the turn/sideways-step ambiguity of a narrow lens
/// leaves the motion undetermined, the rotation block is large (docs/math/two_view.md).
/// Precondition: at least 6 correspondences; returns infinities when the Hessian is singular.
Eigen::Matrix<double, 5, 5> RelativePoseCovariance(const std::vector<Eigen::Vector2d>& x_ref,
                                                   const std::vector<Eigen::Vector2d>& x_cur,
                                                   const RelativePose& pose, double focal_px,
                                                   double huber_px);

}  // namespace parallax
