#include "core/normal_equations.hpp"

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <random>

namespace parallax {
namespace {

template <int N>
Eigen::Matrix<float, N, 1> RandomJacobian(std::mt19937* rng) {
  std::uniform_real_distribution<float> value(-50.0f, 50.0f);
  Eigen::Matrix<float, N, 1> J;
  for (int i = 0; i < N; ++i) J[i] = value(*rng);
  return J;
}

// The block accumulator writes only H's upper triangle; flushed, it must equal a full float
// outer-product accumulation there bit for bit (the trackers' results depend on it) and the
// double per-residual accumulation to float precision.
template <int N>
void ExpectBlockMatchesOuterProducts() {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  BlockAccumulator<N> block;
  Eigen::Matrix<float, N, N> H_full = Eigen::Matrix<float, N, N>::Zero();
  Eigen::Matrix<float, N, 1> g_full = Eigen::Matrix<float, N, 1>::Zero();
  NormalEquations<N> reference;
  for (int k = 0; k < 500; ++k) {
    const Eigen::Matrix<float, N, 1> J = RandomJacobian<N>(&rng);
    const float r = 20.0f * unit(rng) - 10.0f, w = unit(rng), cost = unit(rng);
    block.Add(J, r, w, cost);
    const Eigen::Matrix<float, N, 1> w_J = w * J;
    H_full.noalias() += w_J * J.transpose();
    g_full.noalias() += r * w_J;
    reference.Add(J, r, w, cost);
  }
  NormalEquations<N> flushed;
  block.FlushInto(&flushed);
  EXPECT_EQ(flushed.count, 500);
  EXPECT_NEAR(flushed.cost, reference.cost, 1e-3 * reference.cost);
  for (int j = 0; j < N; ++j) {
    EXPECT_EQ(flushed.g[j], static_cast<double>(g_full[j])) << j;
    for (int i = 0; i <= j; ++i) {
      EXPECT_EQ(flushed.H(i, j), static_cast<double>(H_full(i, j))) << i << "," << j;
      EXPECT_NEAR(flushed.H(i, j), reference.H(i, j), 1e-4 * reference.H.norm()) << i << "," << j;
    }
  }
  const Eigen::Matrix<double, N, N> symmetric = flushed.SymmetricH();
  EXPECT_TRUE(symmetric.isApprox(symmetric.transpose()));
}

TEST(BlockAccumulatorTest, UpperTriangleEqualsFullOuterProductsForSe3Size) {
  ExpectBlockMatchesOuterProducts<8>();
}

TEST(BlockAccumulatorTest, UpperTriangleEqualsFullOuterProductsForSim3Size) {
  ExpectBlockMatchesOuterProducts<9>();
}

TEST(BlockAccumulatorTest, SmallSizesWork) { ExpectBlockMatchesOuterProducts<3>(); }

}  // namespace
}  // namespace parallax
