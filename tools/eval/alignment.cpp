#include "tools/eval/alignment.hpp"

#include <Eigen/Geometry>
#include <cmath>
#include <stdexcept>

#include "core/similarity_fit.hpp"

namespace parallax {

AlignmentMode AlignmentModeFromString(const std::string& name) {
  if (name == "sim3") return AlignmentMode::kSim3;
  if (name == "se3") return AlignmentMode::kSE3;
  if (name == "none") return AlignmentMode::kNone;
  throw std::invalid_argument("unknown alignment '" + name + "' (expected sim3, se3 or none)");
}

std::string ToString(AlignmentMode mode) {
  switch (mode) {
    case AlignmentMode::kSim3:
      return "sim3";
    case AlignmentMode::kSE3:
      return "se3";
    case AlignmentMode::kNone:
      return "none";
  }
  return "none";
}

namespace {

/// Turns R0 about the unit axis `a` (ground-truth frame) by the angle that best aligns the
/// orientations: maximises tr(Rot^T M), M = sum R_y_i R_x_i^T R0^T, whose dependence on the
/// angle is cos(theta) (tr M - a^T M a) + sin(theta) tr([a]x^T M) + const.
Eigen::Matrix3d TurnAboutLine(const Eigen::Matrix3d& R0, const Eigen::Vector3d& a,
                              const std::vector<SO3d>& R_x, const std::vector<SO3d>& R_y) {
  Eigen::Matrix3d M = Eigen::Matrix3d::Zero();
  for (std::size_t i = 0; i < R_x.size(); ++i) {
    M += R_y[i].Matrix() * R_x[i].Matrix().transpose() * R0.transpose();
  }
  Eigen::Matrix3d a_x;
  a_x << 0.0, -a.z(), a.y(), a.z(), 0.0, -a.x(), -a.y(), a.x(), 0.0;
  const double theta = std::atan2((a_x.transpose() * M).trace(), M.trace() - a.dot(M * a));
  return Eigen::AngleAxisd(theta, a).toRotationMatrix() * R0;
}

}  // namespace

Sim3d AlignUmeyama(const std::vector<Eigen::Vector3d>& x, const std::vector<Eigen::Vector3d>& y,
                   AlignmentMode mode, const std::vector<SO3d>& R_x, const std::vector<SO3d>& R_y) {
  if (x.size() != y.size()) throw std::invalid_argument("alignment: point counts differ");
  if (mode == AlignmentMode::kNone) return Sim3d();
  const std::size_t n = x.size();
  if (n < 3) {
    throw std::invalid_argument("alignment needs at least 3 associated poses, got " +
                                std::to_string(n));
  }
  const UmeyamaFit fit = FitUmeyama(x, y);
  const bool collinear = !fit.WellConditioned();
  const bool oriented = R_x.size() == x.size() && R_y.size() == x.size();
  if (!(fit.sigma_x2 > 0.0) || !(fit.singular_values[0] > 0.0) || (collinear && !oriented)) {
    throw std::invalid_argument(
        "alignment is degenerate: the associated positions are (nearly) collinear or constant");
  }
  // R maps the estimate's line onto the ground truth's (first singular vectors); any turn
  // about that line fits the positions equally, and keeps the scale tr(D S) / sigma_x^2.
  const Eigen::Matrix3d R = collinear ? TurnAboutLine(fit.R, fit.U.col(0), R_x, R_y) : fit.R;
  const double s = mode == AlignmentMode::kSim3 ? fit.scale : 1.0;
  return Sim3d(s, SO3d(R), fit.mu_y - s * R * fit.mu_x);
}

}  // namespace parallax
