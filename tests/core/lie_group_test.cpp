// Property tests shared by SO3, SE3 and Sim3 in float and double (in the spirit of Sophus'
// LieGroupTests): round trips, group axioms, Exp against the matrix exponential, adjoint,
// and every analytic Jacobian against numeric differentiation.

#include <gtest/gtest.h>

#include <numbers>
#include <unsupported/Eigen/MatrixFunctions>

#include "core/se3.hpp"
#include "core/sim3.hpp"
#include "core/so3.hpp"
#include "tests/core/lie_test_utils.hpp"

namespace parallax {
namespace {

using test::NumericJacobian;
using test::RandomVector;

template <typename G>
constexpr double Tolerance() {
  return std::is_same_v<typename G::Tangent::Scalar, float> ? 2e-4 : 1e-9;
}

// Random tangent with rotation angle < 3 rad, translation < 2, log-scale < 1.
template <typename G>
typename G::Tangent RandomTangent(std::mt19937_64& rng) {
  using Scalar = typename G::Tangent::Scalar;
  Eigen::Matrix<double, G::kDoF, 1> xi = RandomVector<G::kDoF>(rng, 2.0);
  if constexpr (G::kDoF == 3) {
    xi = xi.normalized() * std::uniform_real_distribution<double>(0.0, 3.0)(rng);
  } else {
    xi.template segment<3>(3) = xi.template segment<3>(3).normalized() *
                                std::uniform_real_distribution<double>(0.0, 3.0)(rng);
    if constexpr (G::kDoF == 7) xi[6] *= 0.5;
  }
  return xi.template cast<Scalar>();
}

// The group element as a homogeneous (or rotation) matrix in double.
template <typename G>
Eigen::MatrixXd AsMatrix(const G& g) {
  return g.Matrix().template cast<double>();
}

// |a - b| <= tol * max(1, |b|), compared in double.
template <typename A, typename B>
bool Near(const A& a, const B& b, double tol) {
  const Eigen::MatrixXd ad = a.template cast<double>();
  const Eigen::MatrixXd bd = b.template cast<double>();
  return (ad - bd).norm() <= tol * std::max(1.0, bd.norm());
}

template <typename G>
Eigen::MatrixXd HatOf(const typename G::Tangent& xi) {
  return G::Hat(xi).template cast<double>();
}

template <typename G>
class LieGroupTest : public ::testing::Test {
 protected:
  std::mt19937_64 rng_{42};
};

using Groups = ::testing::Types<SO3f, SO3d, SE3f, SE3d, Sim3f, Sim3d>;
TYPED_TEST_SUITE(LieGroupTest, Groups);

TYPED_TEST(LieGroupTest, ExpLogRoundTripRandom) {
  for (int i = 0; i < 200; ++i) {
    const auto xi = RandomTangent<TypeParam>(this->rng_);
    const auto g = TypeParam::Exp(xi);
    EXPECT_TRUE(Near(g.Log(), xi, Tolerance<TypeParam>() * 10))
        << "xi = " << xi.transpose() << "\nlog = " << g.Log().transpose();
    EXPECT_TRUE(AsMatrix(TypeParam::Exp(g.Log())).isApprox(AsMatrix(g), Tolerance<TypeParam>()));
  }
}

TYPED_TEST(LieGroupTest, ExpLogRoundTripNearZero) {
  for (const double scale : {0.0, 1e-12, 1e-9, 1e-6, 1e-4, 1e-2}) {
    auto xi = RandomTangent<TypeParam>(this->rng_);
    xi = (xi.template cast<double>().normalized() * scale)
             .template cast<typename TypeParam::Tangent::Scalar>();
    const auto g = TypeParam::Exp(xi);
    EXPECT_LT((g.Log() - xi).norm(), Tolerance<TypeParam>() * 1e-2 + 1e-15) << "scale " << scale;
    // First-order agreement with the Lie algebra: Exp(xi) ~= I + hat(xi).
    const Eigen::MatrixXd I = Eigen::MatrixXd::Identity(AsMatrix(g).rows(), AsMatrix(g).cols());
    EXPECT_LT((AsMatrix(g) - I - HatOf<TypeParam>(xi)).norm(), scale * scale + 1e-6);
  }
}

TYPED_TEST(LieGroupTest, ExpLogRoundTripNearPi) {
  using Scalar = typename TypeParam::Tangent::Scalar;
  for (const double eps : {0.0, 1e-9, 1e-6, 1e-3}) {
    auto xi = RandomTangent<TypeParam>(this->rng_);
    Eigen::Matrix<double, TypeParam::kDoF, 1> x = xi.template cast<double>();
    const int r = TypeParam::kDoF == 3 ? 0 : 3;
    x.template segment<3>(r) = x.template segment<3>(r).normalized() * (std::numbers::pi - eps);
    const auto g = TypeParam::Exp(x.template cast<Scalar>());
    const auto log = g.Log();
    EXPECT_LE(log.template segment<3>(r).norm(), std::numbers::pi + 1e-6);
    EXPECT_TRUE(AsMatrix(TypeParam::Exp(log)).isApprox(AsMatrix(g), Tolerance<TypeParam>() * 10));
  }
}

TYPED_TEST(LieGroupTest, ExpMatchesMatrixExponential) {
  for (int i = 0; i < 50; ++i) {
    const auto xi = RandomTangent<TypeParam>(this->rng_);
    const Eigen::MatrixXd expected = HatOf<TypeParam>(xi).exp();
    EXPECT_TRUE(AsMatrix(TypeParam::Exp(xi)).isApprox(expected, Tolerance<TypeParam>()))
        << "xi = " << xi.transpose();
  }
}

TYPED_TEST(LieGroupTest, HatVeeRoundTrip) {
  const auto xi = RandomTangent<TypeParam>(this->rng_);
  EXPECT_TRUE(TypeParam::Vee(TypeParam::Hat(xi)).isApprox(xi));
}

TYPED_TEST(LieGroupTest, InverseAndComposition) {
  using Vec3 = Eigen::Matrix<typename TypeParam::Tangent::Scalar, 3, 1>;
  for (int i = 0; i < 50; ++i) {
    const auto a = TypeParam::Exp(RandomTangent<TypeParam>(this->rng_));
    const auto b = TypeParam::Exp(RandomTangent<TypeParam>(this->rng_));
    const auto c = TypeParam::Exp(RandomTangent<TypeParam>(this->rng_));
    const Vec3 p = RandomVector<3>(this->rng_, 3.0).template cast<typename Vec3::Scalar>();
    EXPECT_LT((a * a.Inverse()).Log().norm(), Tolerance<TypeParam>());
    EXPECT_TRUE(AsMatrix((a * b) * c).isApprox(AsMatrix(a * (b * c)), Tolerance<TypeParam>()));
    EXPECT_TRUE(Near((a * b) * p, a * (b * p), Tolerance<TypeParam>() * 10));
    EXPECT_TRUE(Near(a.Inverse() * (a * p), p, Tolerance<TypeParam>() * 100));
    EXPECT_TRUE(AsMatrix(a * b).isApprox(AsMatrix(a) * AsMatrix(b), Tolerance<TypeParam>()));
  }
}

TYPED_TEST(LieGroupTest, AdjointConjugatesTangents) {
  for (int i = 0; i < 50; ++i) {
    const auto g = TypeParam::Exp(RandomTangent<TypeParam>(this->rng_));
    const auto xi = RandomTangent<TypeParam>(this->rng_);
    const auto lhs = g * TypeParam::Exp(xi) * g.Inverse();
    const auto rhs = TypeParam::Exp(g.Adjoint() * xi);
    EXPECT_TRUE(AsMatrix(lhs).isApprox(AsMatrix(rhs), Tolerance<TypeParam>() * 10));
  }
}

TYPED_TEST(LieGroupTest, ActionJacobianMatchesNumeric) {
  using Scalar = typename TypeParam::Tangent::Scalar;
  using GroupD = decltype(TypeParam().template Cast<double>());
  for (int i = 0; i < 20; ++i) {
    const auto g = TypeParam::Exp(RandomTangent<TypeParam>(this->rng_));
    const Eigen::Vector3d p = RandomVector<3>(this->rng_, 3.0);
    const GroupD gd = g.template Cast<double>();
    const auto numeric = NumericJacobian<3, TypeParam::kDoF>(
        [&](const Eigen::Matrix<double, TypeParam::kDoF, 1>& d) {
          return Eigen::Vector3d(GroupD::Exp(d) * gd * p);
        },
        Eigen::Matrix<double, TypeParam::kDoF, 1>::Zero());
    const Eigen::MatrixXd analytic =
        g.JacobianActionLeftPerturbation(p.cast<Scalar>()).template cast<double>();
    EXPECT_LT((analytic - numeric).norm(), Tolerance<TypeParam>() * 1e3 * (1.0 + numeric.norm()));
  }
}

TYPED_TEST(LieGroupTest, LongCompositionStaysOnManifold) {
  auto g = TypeParam();
  using Scalar = typename TypeParam::Tangent::Scalar;
  const auto step = TypeParam::Exp(RandomTangent<TypeParam>(this->rng_) * Scalar(0.01));
  for (int i = 0; i < 10000; ++i) g = g * step;
  Eigen::Matrix3d R;
  if constexpr (TypeParam::kDoF == 3) {
    R = g.Matrix().template cast<double>();
  } else {
    R = g.Rotation().Matrix().template cast<double>();
  }
  EXPECT_LT((R.transpose() * R - Eigen::Matrix3d::Identity()).norm(), Tolerance<TypeParam>());
}

TYPED_TEST(LieGroupTest, CastPreservesElement) {
  const auto g = TypeParam::Exp(RandomTangent<TypeParam>(this->rng_));
  const auto round_trip =
      g.template Cast<double>().template Cast<typename TypeParam::Tangent::Scalar>();
  EXPECT_TRUE(AsMatrix(round_trip).isApprox(AsMatrix(g), Tolerance<TypeParam>()));
}

}  // namespace
}  // namespace parallax
