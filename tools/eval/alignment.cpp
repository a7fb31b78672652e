#include "tools/eval/alignment.hpp"

#include <Eigen/SVD>
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

Sim3d AlignUmeyama(const std::vector<Eigen::Vector3d>& x, const std::vector<Eigen::Vector3d>& y,
                   AlignmentMode mode) {
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
  if (!(sigma_x2 > 0.0) || !(d[0] > 0.0) || d[1] < 1e-10 * d[0]) {
    throw std::invalid_argument(
        "alignment is degenerate: the associated positions are (nearly) collinear or constant");
  }
  Eigen::Matrix3d S = Eigen::Matrix3d::Identity();
  if (svd.matrixU().determinant() * svd.matrixV().determinant() < 0.0) S(2, 2) = -1.0;
  const Eigen::Matrix3d R = svd.matrixU() * S * svd.matrixV().transpose();
  const double s = mode == AlignmentMode::kSim3 ? (d.asDiagonal() * S).trace() / sigma_x2 : 1.0;
  return Sim3d(s, SO3d(R), mu_y - s * R * mu_x);
}

}  // namespace parallax
