#pragma once
// Angles between directions, in degrees (thresholds in options are given in degrees).

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <numbers>

namespace parallax {

inline constexpr double kRadToDeg = 180.0 / std::numbers::pi;

/// Angle between two directions, degrees in [0, 180]; 180 when either is zero (no direction
/// agrees with a missing one).
inline double AngleBetweenDeg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  const double norms = a.norm() * b.norm();
  if (!(norms > 0.0)) return 180.0;
  return std::acos(std::clamp(a.dot(b) / norms, -1.0, 1.0)) * kRadToDeg;
}

}  // namespace parallax
