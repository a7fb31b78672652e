#pragma once
// Gauss-Newton normal equations H dx = -g accumulated from weighted residuals, reducible so
// that partial sums over blocks of points can be added in a fixed order (deterministic).

#include <Eigen/Core>
#include <algorithm>

namespace parallax {

/// Accumulates H = sum w J J^T, g = sum w J r and the robust cost for N parameters.
/// Per-residual terms are float (the hot loop), sums are double so that tens of thousands of
/// terms do not lose precision.
template <int N>
struct NormalEquations {
  Eigen::Matrix<double, N, N> H = Eigen::Matrix<double, N, N>::Zero();
  Eigen::Matrix<double, N, 1> g = Eigen::Matrix<double, N, 1>::Zero();
  double cost = 0.0;  ///< sum of robust costs
  int count = 0;      ///< residuals added

  /// Adds one residual r with Jacobian J (1xN as a column), weight w and robust cost.
  void Add(const Eigen::Matrix<float, N, 1>& J, float r, float w, float robust_cost) {
    const Eigen::Matrix<double, N, 1> Jd = J.template cast<double>();
    H.template selfadjointView<Eigen::Upper>().rankUpdate(Jd, static_cast<double>(w));
    g.noalias() += (static_cast<double>(w) * static_cast<double>(r)) * Jd;
    cost += static_cast<double>(robust_cost);
    ++count;
  }

  NormalEquations& operator+=(const NormalEquations& other) {
    H += other.H;
    g += other.g;
    cost += other.cost;
    count += other.count;
    return *this;
  }

  /// H with its lower triangle filled from the upper one (Add only writes the upper).
  Eigen::Matrix<double, N, N> SymmetricH() const {
    return H.template selfadjointView<Eigen::Upper>();
  }
};

/// Float accumulator for one block of a few thousand residuals: full fixed-size outer
/// products vectorise well, where a per-residual double rank update does not. Flush() adds the
/// block into double NormalEquations (keeps the sum precise over many blocks).
template <int N>
struct BlockAccumulator {
  Eigen::Matrix<float, N, N> H = Eigen::Matrix<float, N, N>::Zero();
  Eigen::Matrix<float, N, 1> g = Eigen::Matrix<float, N, 1>::Zero();
  float cost = 0.0f;
  int count = 0;

  void Add(const Eigen::Matrix<float, N, 1>& J, float r, float w, float robust_cost) {
    const Eigen::Matrix<float, N, 1> w_J = w * J;
    // Column by column (inlined and vectorised, unlike Eigen's outer product here), and only
    // down to the first multiple of 4 rows that covers the upper triangle: FlushInto reads
    // nothing else. Every entry written gets the product and sum a full outer product gives.
    constexpr int kFirst = std::min(N, 4), kSecond = std::min(N, 8);
    for (int j = 0; j < kFirst; ++j) {
      H.col(j).template head<kFirst>() += w_J.template head<kFirst>() * J[j];
    }
    for (int j = kFirst; j < kSecond; ++j) {
      H.col(j).template head<kSecond>() += w_J.template head<kSecond>() * J[j];
    }
    for (int j = kSecond; j < N; ++j) H.col(j) += w_J * J[j];
    g.noalias() += r * w_J;
    cost += robust_cost;
    ++count;
  }

  void FlushInto(NormalEquations<N>* out) const {
    out->H += H.template cast<double>().template triangularView<Eigen::Upper>().toDenseMatrix();
    out->g += g.template cast<double>();
    out->cost += static_cast<double>(cost);
    out->count += count;
  }
};

}  // namespace parallax
