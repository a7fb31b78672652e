#pragma once
// Least-squares similarity between two point sets (Umeyama 1991), shared by trajectory
// evaluation and the place recogniser's Sim(3) RANSAC.

#include <Eigen/Core>
#include <optional>
#include <span>

#include "core/sim3.hpp"

namespace parallax {

/// The pieces of Umeyama's closed form for y ~ s R x + t:
/// Sigma_xy = 1/n sum (y - mu_y)(x - mu_x)^T = U D V^T, R = U S V^T with
/// S = diag(1, 1, det(U V^T)), s = tr(D S) / sigma_x^2, t = mu_y - s R mu_x.
struct UmeyamaFit {
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  double scale = 1.0;  ///< tr(D S) / sigma_x^2 (whether or not the caller wants scale)
  Eigen::Vector3d mu_x = Eigen::Vector3d::Zero();
  Eigen::Vector3d mu_y = Eigen::Vector3d::Zero();
  Eigen::Vector3d singular_values = Eigen::Vector3d::Zero();  ///< D, descending
  Eigen::Matrix3d U = Eigen::Matrix3d::Identity();
  double sigma_x2 = 0.0;  ///< 1/n sum |x - mu_x|^2

  /// The first two singular values are well apart from zero (the points span a plane):
  /// `relative` is the smallest acceptable ratio D[1] / D[0].
  bool WellConditioned(double relative = 1e-10) const {
    return sigma_x2 > 0.0 && singular_values[0] > 0.0 &&
           singular_values[1] >= relative * singular_values[0];
  }
  /// s R x + t with the fitted scale (or 1).
  Sim3d Similarity(bool with_scale) const;
};

/// Umeyama's statistics for the pairs (x_i, y_i). Precondition: equal sizes (checked).
UmeyamaFit FitUmeyama(std::span<const Eigen::Vector3d> x, std::span<const Eigen::Vector3d> y);

/// S minimising sum |y_i - S x_i|^2, or nullopt when the points are degenerate (fewer than
/// 3, all equal, or collinear within `relative` of the largest singular value) or the
/// result is not a valid similarity.
std::optional<Sim3d> FitSimilarity(std::span<const Eigen::Vector3d> x,
                                   std::span<const Eigen::Vector3d> y, bool with_scale,
                                   double relative = 1e-10);

}  // namespace parallax
