#include "core/similarity_fit.hpp"

#include <Eigen/SVD>
#include <cmath>

#include "core/check.hpp"

namespace parallax {

Sim3d UmeyamaFit::Similarity(bool with_scale) const {
  const double s = with_scale ? scale : 1.0;
  return Sim3d(s, SO3d(R), mu_y - s * R * mu_x);
}

UmeyamaFit FitUmeyama(std::span<const Eigen::Vector3d> x, std::span<const Eigen::Vector3d> y) {
  CheckArgument(x.size() == y.size(), "FitUmeyama: point counts differ");
  UmeyamaFit fit;
  const std::size_t n = x.size();
  if (n == 0) return fit;
  for (std::size_t i = 0; i < n; ++i) {
    fit.mu_x += x[i];
    fit.mu_y += y[i];
  }
  fit.mu_x /= static_cast<double>(n);
  fit.mu_y /= static_cast<double>(n);
  Eigen::Matrix3d sigma_xy = Eigen::Matrix3d::Zero();
  for (std::size_t i = 0; i < n; ++i) {
    fit.sigma_x2 += (x[i] - fit.mu_x).squaredNorm();
    sigma_xy += (y[i] - fit.mu_y) * (x[i] - fit.mu_x).transpose();
  }
  fit.sigma_x2 /= static_cast<double>(n);
  sigma_xy /= static_cast<double>(n);
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(sigma_xy, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Eigen::Vector3d d = svd.singularValues();
  fit.singular_values = d;
  fit.U = svd.matrixU();
  Eigen::Matrix3d S = Eigen::Matrix3d::Identity();
  if (svd.matrixU().determinant() * svd.matrixV().determinant() < 0.0) S(2, 2) = -1.0;
  fit.R = svd.matrixU() * S * svd.matrixV().transpose();
  fit.scale = fit.sigma_x2 > 0.0 ? (d.asDiagonal() * S).trace() / fit.sigma_x2 : 1.0;
  return fit;
}

std::optional<Sim3d> FitSimilarity(std::span<const Eigen::Vector3d> x,
                                   std::span<const Eigen::Vector3d> y, bool with_scale,
                                   double relative) {
  if (x.size() != y.size() || x.size() < 3) return std::nullopt;
  const UmeyamaFit fit = FitUmeyama(x, y);
  if (!fit.WellConditioned(relative)) return std::nullopt;
  if (with_scale && !(fit.scale > 0.0 && std::isfinite(fit.scale))) return std::nullopt;
  if (!fit.R.allFinite() || !fit.mu_y.allFinite()) return std::nullopt;
  return fit.Similarity(with_scale);
}

}  // namespace parallax
