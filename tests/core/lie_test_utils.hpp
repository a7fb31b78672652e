#pragma once
// Helpers shared by the Lie group tests: random tangents and numeric differentiation.

#include <Eigen/Core>
#include <cstdint>
#include <random>

namespace parallax::test {

/// Deterministic random vector with entries uniform in [-range, range].
template <int N>
Eigen::Matrix<double, N, 1> RandomVector(std::mt19937_64& rng, double range) {
  std::uniform_real_distribution<double> uniform(-range, range);
  Eigen::Matrix<double, N, 1> v;
  for (int i = 0; i < N; ++i) v[i] = uniform(rng);
  return v;
}

/// Central-difference Jacobian of f: R^N -> R^M at x (double precision).
template <int M, int N, typename F>
Eigen::Matrix<double, M, N> NumericJacobian(F f, const Eigen::Matrix<double, N, 1>& x,
                                            double step = 1e-6) {
  Eigen::Matrix<double, M, N> J;
  for (int i = 0; i < N; ++i) {
    Eigen::Matrix<double, N, 1> plus = x;
    Eigen::Matrix<double, N, 1> minus = x;
    plus[i] += step;
    minus[i] -= step;
    J.col(i) = (f(plus) - f(minus)) / (2.0 * step);
  }
  return J;
}

}  // namespace parallax::test
