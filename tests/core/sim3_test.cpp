// Sim(3)-specific tests: the W coefficients, scale handling, invalid input.

#include "core/sim3.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <unsupported/Eigen/MatrixFunctions>

#include "core/divergence.hpp"
#include "core/lie_coefficients.hpp"
#include "tests/core/lie_test_utils.hpp"

namespace parallax {
namespace {

using test::RandomVector;

// Closed forms of the W coefficients, valid away from theta = 0 and sigma = 0.
lie_detail::SimilarityCoefficients ClosedForm(double theta, double sigma) {
  const double s = std::exp(sigma);
  const double d = sigma * sigma + theta * theta;
  const double a = (s - 1.0) / sigma;
  const double int_sin = (s * (sigma * std::sin(theta) - theta * std::cos(theta)) + theta) / d;
  const double int_cos = (s * (sigma * std::cos(theta) + theta * std::sin(theta)) - sigma) / d;
  return {a, int_sin / theta, (a - int_cos) / (theta * theta)};
}

TEST(SimilarityCoefficients, MatchClosedFormAwayFromSingularities) {
  for (const double theta : {0.3, 1.0, 2.5, 3.1}) {
    for (const double sigma : {-2.0, -0.4, 0.3, 1.5}) {
      const auto q = lie_detail::ComputeSimilarityCoefficients(theta, sigma);
      const auto c = ClosedForm(theta, sigma);
      EXPECT_NEAR(q.a, c.a, 1e-13);
      EXPECT_NEAR(q.b, c.b, 1e-13);
      EXPECT_NEAR(q.c, c.c, 1e-13);
    }
  }
}

TEST(SimilarityCoefficients, LimitsAtZero) {
  const auto k = lie_detail::ComputeSimilarityCoefficients(0.0, 0.0);
  EXPECT_NEAR(k.a, 1.0, 1e-15);
  EXPECT_NEAR(k.b, 0.5, 1e-15);
  EXPECT_NEAR(k.c, 1.0 / 6.0, 1e-15);
  // sigma = 0 reduces W to the SE(3) V matrix coefficients.
  const auto se3 = lie_detail::ComputeSimilarityCoefficients(1.2, 0.0);
  EXPECT_NEAR(se3.b, lie_detail::OneMinusCosOverSq(1.2), 1e-14);
  EXPECT_NEAR(se3.c, lie_detail::ThetaMinusSinOverCube(1.2), 1e-14);
}

TEST(Sim3, TranslationMatchesMatrixExponentialForLargeScale) {
  std::mt19937_64 rng(3);
  for (const double sigma : {-3.0, -1e-7, 1e-9, 2.5}) {
    Eigen::Matrix<double, 7, 1> xi;
    xi << RandomVector<3>(rng, 1.0), RandomVector<3>(rng, 1.0), sigma;
    const Eigen::Matrix4d expected = Sim3d::Hat(xi).exp();
    EXPECT_TRUE(Sim3d::Exp(xi).Matrix().isApprox(expected, 1e-12)) << "sigma " << sigma;
    EXPECT_NEAR(Sim3d::Exp(xi).Scale(), std::exp(sigma), 1e-12 * std::exp(sigma));
  }
}

TEST(Sim3, ZeroLogScaleEqualsSE3) {
  std::mt19937_64 rng(4);
  Eigen::Matrix<double, 6, 1> xi6 = RandomVector<6>(rng, 1.0);
  Eigen::Matrix<double, 7, 1> xi7;
  xi7 << xi6, 0.0;
  EXPECT_TRUE(Sim3d::Exp(xi7).Matrix().isApprox(SE3d::Exp(xi6).Matrix(), 1e-13));
  EXPECT_TRUE(Sim3d(SE3d::Exp(xi6)).Log().isApprox(xi7, 1e-12));
}

TEST(Sim3, ScaleComposesMultiplicatively) {
  const Sim3d a(2.0, SO3d(), Eigen::Vector3d(1, 0, 0));
  const Sim3d b(0.25, SO3d::Exp(Eigen::Vector3d(0.1, 0.2, 0.3)), Eigen::Vector3d(0, 1, 0));
  EXPECT_DOUBLE_EQ((a * b).Scale(), 0.5);
  EXPECT_DOUBLE_EQ(a.Inverse().Scale(), 0.5);
  EXPECT_TRUE((a * Eigen::Vector3d(1, 1, 1)).isApprox(Eigen::Vector3d(3, 2, 2)));
}

TEST(Sim3, RejectsNonPositiveOrNonFiniteScale) {
  // Numerical divergence (docs/reliability.md), which is also bad input to a caller.
  EXPECT_THROW(Sim3d(0.0, SO3d(), Eigen::Vector3d::Zero()), NumericalDivergence);
  EXPECT_THROW(Sim3d(-1.0, SO3d(), Eigen::Vector3d::Zero()), NumericalDivergence);
  EXPECT_THROW(Sim3d(NAN, SO3d(), Eigen::Vector3d::Zero()), NumericalDivergence);
  EXPECT_THROW(Sim3d(1.0, SO3d(), Eigen::Vector3d(0, INFINITY, 0)), NumericalDivergence);
  EXPECT_THROW(Sim3d(0.0, SO3d(), Eigen::Vector3d::Zero()), std::invalid_argument);
  Eigen::Matrix<float, 7, 1> huge = Eigen::Matrix<float, 7, 1>::Zero();
  huge[6] = 200.0f;  // exp(200) overflows float: must be reported, not propagated
  EXPECT_THROW(Sim3f::Exp(huge), NumericalDivergence);
}

}  // namespace
}  // namespace parallax
