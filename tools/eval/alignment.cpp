#include "tools/eval/alignment.hpp"

#include <Eigen/Geometry>
#include <Eigen/SVD>
#include <cmath>
#include <stdexcept>

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
  Eigen::Vector3d mu_x = Eigen::Vector3d::Zero();
  Eigen::Vector3d mu_y = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < n; ++i) {
    mu_x += x[i];
    mu_y += y[i];
  }
  mu_x /= static_cast<double>(n);
  mu_y /= static_cast<double>(n);
  double sigma_x2 = 0.0;
  Eigen::Matrix3d sigma_xy = Eigen::Matrix3d::Zero();
  for (std::size_t i = 0; i < n; ++i) {
    sigma_x2 += (x[i] - mu_x).squaredNorm();
    sigma_xy += (y[i] - mu_y) * (x[i] - mu_x).transpose();
  }
  sigma_x2 /= static_cast<double>(n);
  sigma_xy /= static_cast<double>(n);
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(sigma_xy, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Eigen::Vector3d d = svd.singularValues();
  const bool collinear = d[1] < 1e-10 * d[0];
  const bool oriented = R_x.size() == x.size() && R_y.size() == x.size();
  if (!(sigma_x2 > 0.0) || !(d[0] > 0.0) || (collinear && !oriented)) {
    throw std::invalid_argument(
        "alignment is degenerate: the associated positions are (nearly) collinear or constant");
  }
  Eigen::Matrix3d S = Eigen::Matrix3d::Identity();
  if (svd.matrixU().determinant() * svd.matrixV().determinant() < 0.0) S(2, 2) = -1.0;
  Eigen::Matrix3d R = svd.matrixU() * S * svd.matrixV().transpose();
  // R maps the estimate's line onto the ground truth's (first singular vectors); any turn
  // about that line fits the positions equally, and keeps the scale tr(D S) / sigma_x^2.
  if (collinear) R = TurnAboutLine(R, svd.matrixU().col(0), R_x, R_y);
  const double s = mode == AlignmentMode::kSim3 ? (d.asDiagonal() * S).trace() / sigma_x2 : 1.0;
  return Sim3d(s, SO3d(R), mu_y - s * R * mu_x);
}

}  // namespace parallax
