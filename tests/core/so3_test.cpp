// SO(3)- and SE(3)-specific tests: Jacobians of the exponential, invalid input, known values.

#include "core/so3.hpp"

#include <gtest/gtest.h>

#include <numbers>

#include "core/divergence.hpp"
#include "core/se3.hpp"
#include "tests/core/lie_test_utils.hpp"

namespace parallax {
namespace {

using test::NumericJacobian;
using test::RandomVector;

TEST(SO3, KnownRotationAboutZ) {
  const SO3d R = SO3d::Exp(Eigen::Vector3d(0, 0, std::numbers::pi / 2));
  EXPECT_TRUE((R * Eigen::Vector3d(1, 0, 0)).isApprox(Eigen::Vector3d(0, 1, 0)));
  EXPECT_TRUE((R * Eigen::Vector3d(0, 1, 0)).isApprox(Eigen::Vector3d(-1, 0, 0)));
}

TEST(SO3, LeftJacobianMatchesNumeric) {
  // Exp(omega + d) = Exp(J_l(omega) d) Exp(omega) to first order, so
  // J_l = d/dd Log(Exp(omega + d) Exp(omega)^-1) at d = 0.
  std::mt19937_64 rng(7);
  for (const double angle : {0.0, 1e-7, 1e-3, 0.5, 2.0, 3.1}) {
    const Eigen::Vector3d omega = RandomVector<3>(rng, 1.0).normalized() * angle;
    const SO3d R_inv = SO3d::Exp(omega).Inverse();
    const Eigen::Matrix3d numeric = NumericJacobian<3, 3>(
        [&](const Eigen::Vector3d& d) {
          return Eigen::Vector3d((SO3d::Exp(omega + d) * R_inv).Log());
        },
        Eigen::Vector3d::Zero());
    EXPECT_LT((SO3d::LeftJacobian(omega) - numeric).norm(), 1e-8) << "angle " << angle;
    EXPECT_TRUE((SO3d::LeftJacobianInverse(omega) * SO3d::LeftJacobian(omega))
                    .isApprox(Eigen::Matrix3d::Identity(), 1e-10))
        << "angle " << angle;
  }
}

TEST(SO3, LogJacobianIsLeftJacobianInverse) {
  // d Log(Exp(d) R) / dd = J_l^-1(Log R).
  std::mt19937_64 rng(8);
  for (int i = 0; i < 20; ++i) {
    const Eigen::Vector3d omega = RandomVector<3>(rng, 1.5);
    const SO3d R = SO3d::Exp(omega);
    const Eigen::Matrix3d numeric = NumericJacobian<3, 3>(
        [&](const Eigen::Vector3d& d) { return Eigen::Vector3d((SO3d::Exp(d) * R).Log()); },
        Eigen::Vector3d::Zero());
    EXPECT_LT((SO3d::LeftJacobianInverse(omega) - numeric).norm(), 1e-7);
  }
}

TEST(SO3, RejectsInvalidInput) {
  EXPECT_THROW(SO3d(Eigen::Quaterniond(0, 0, 0, 0)), NumericalDivergence);
  EXPECT_THROW(SO3d(Eigen::Quaterniond(NAN, 0, 0, 1)), NumericalDivergence);
  EXPECT_THROW(SO3d(Eigen::Matrix3d::Constant(NAN)), NumericalDivergence);
  EXPECT_THROW(SO3d(Eigen::Matrix3d(2.0 * Eigen::Matrix3d::Identity())), std::invalid_argument);
  Eigen::Matrix3d reflection = Eigen::Matrix3d::Identity();
  reflection(2, 2) = -1.0;
  EXPECT_THROW(SO3d{reflection}, std::invalid_argument);
  // A non-unit quaternion is accepted and normalised.
  const SO3d R(Eigen::Quaterniond(2, 0, 0, 0));
  EXPECT_NEAR(R.UnitQuaternion().norm(), 1.0, 1e-15);
}

TEST(SO3, FromMatrixRoundTrip) {
  std::mt19937_64 rng(9);
  const SO3d R = SO3d::Exp(RandomVector<3>(rng, 2.0));
  EXPECT_TRUE(SO3d(R.Matrix()).Matrix().isApprox(R.Matrix(), 1e-12));
}

TEST(SE3, TranslationFirstTangentOrder) {
  Eigen::Matrix<double, 6, 1> xi;
  xi << 1, 2, 3, 0, 0, 0;  // pure translation
  const SE3d T = SE3d::Exp(xi);
  EXPECT_TRUE(T.Translation().isApprox(Eigen::Vector3d(1, 2, 3)));
  EXPECT_TRUE(T.RotationMatrix().isApprox(Eigen::Matrix3d::Identity()));
}

TEST(SE3, PointFrameConvention) {
  // T_w_c maps camera points to world: a camera at (1, 0, 0) looking along +z sees the world
  // origin at (-1, 0, 0).
  const SE3d T_w_c(SO3d(), Eigen::Vector3d(1, 0, 0));
  EXPECT_TRUE((T_w_c.Inverse() * Eigen::Vector3d::Zero()).isApprox(Eigen::Vector3d(-1, 0, 0)));
  EXPECT_TRUE((T_w_c * Eigen::Vector3d::Zero()).isApprox(Eigen::Vector3d(1, 0, 0)));
}

TEST(SE3, RejectsInvalidInput) {
  EXPECT_THROW(SE3d(SO3d(), Eigen::Vector3d(NAN, 0, 0)), NumericalDivergence);
  Eigen::Matrix4d bad = Eigen::Matrix4d::Identity();
  bad(3, 0) = 1.0;
  EXPECT_THROW(SE3d{bad}, std::invalid_argument);
}

TEST(SE3, LogJacobianMatchesLeftJacobianInverseAtIdentity) {
  // Near the identity, d Log(Exp(d) T) / dd ~= J_l^-1(xi) of SE(3); at T = I it is I.
  const Eigen::Matrix<double, 6, 6> numeric = NumericJacobian<6, 6>(
      [](const Eigen::Matrix<double, 6, 1>& d) {
        return Eigen::Matrix<double, 6, 1>(SE3d::Exp(d).Log());
      },
      Eigen::Matrix<double, 6, 1>::Zero());
  EXPECT_TRUE(numeric.isApprox(Eigen::Matrix<double, 6, 6>::Identity(), 1e-8));
}

}  // namespace
}  // namespace parallax
