#pragma once
// Least-squares alignment of point sets (Umeyama 1991).

#include <Eigen/Core>
#include <string>
#include <vector>

#include "core/sim3.hpp"

namespace parallax {

enum class AlignmentMode {
  kSim3,  ///< rotation, translation and scale (monocular)
  kSE3,   ///< rotation and translation
  kNone,  ///< identity
};

/// "sim3", "se3", "none"; throws std::invalid_argument otherwise.
AlignmentMode AlignmentModeFromString(const std::string& name);
std::string ToString(AlignmentMode mode);

/// S minimising sum |y_i - S x_i|^2 (x = estimate, y = ground truth), Umeyama's closed form:
/// Sigma_xy = 1/n sum (y - mu_y)(x - mu_x)^T = U D V^T, R = U diag(1, 1, det(UV^T)) V^T,
/// s = tr(D S) / sigma_x^2, t = mu_y - s R mu_x (s = 1 for kSE3).
/// Collinear points (the second singular value of Sigma_xy below 1e-10 of the first) fix
/// everything but the rotation about the line; when orientations are given (R_x: estimate,
/// R_y: ground truth, one per point) that angle is the one that best aligns them,
/// argmax_theta sum tr((Rot(a, theta) R0 R_x_i)^T R_y_i), in closed form (docs/evaluation.md).
/// Throws std::invalid_argument for fewer than 3 pairs, collinear points without
/// orientations, or all estimate points equal.
Sim3d AlignUmeyama(const std::vector<Eigen::Vector3d>& x, const std::vector<Eigen::Vector3d>& y,
                   AlignmentMode mode, const std::vector<SO3d>& R_x = {},
                   const std::vector<SO3d>& R_y = {});

}  // namespace parallax
