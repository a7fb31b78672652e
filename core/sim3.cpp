#include "core/sim3.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

#include "core/divergence.hpp"
#include "core/lie_coefficients.hpp"

namespace parallax {
namespace {

// W = a I + b [omega]_x + c [omega]_x^2 (docs/math/lie_groups.md, "Sim(3) exponential").
Eigen::Matrix3d SimilarityW(const Eigen::Vector3d& omega, double sigma) {
  const auto k = lie_detail::ComputeSimilarityCoefficients(omega.norm(), sigma);
  const Eigen::Matrix3d W = SO3d::Hat(omega);
  return k.a * Eigen::Matrix3d::Identity() + k.b * W + k.c * W * W;
}

}  // namespace

template <typename Scalar>
Sim3<Scalar>::Sim3(Scalar scale, const SO3<Scalar>& rotation, const Vector3& translation)
    : scale_(scale), rotation_(rotation), translation_(translation) {
  if (!std::isfinite(scale) || !(scale > Scalar(0))) {
    throw NumericalDivergence("Sim3: scale must be finite and > 0, got " + std::to_string(scale));
  }
  if (!translation.allFinite()) throw NumericalDivergence("Sim3: translation must be finite");
}

template <typename Scalar>
Sim3<Scalar>::Sim3(const SE3<Scalar>& rigid)
    : scale_(1), rotation_(rigid.Rotation()), translation_(rigid.Translation()) {}

template <typename Scalar>
Sim3<Scalar> Sim3<Scalar>::Exp(const Tangent& xi) {
  const Eigen::Matrix<double, 7, 1> x = xi.template cast<double>();
  const Eigen::Vector3d omega = x.segment<3>(3);
  const double sigma = x[6];
  const Eigen::Vector3d t = SimilarityW(omega, sigma) * x.head<3>();
  return Sim3(static_cast<Scalar>(std::exp(sigma)), SO3<Scalar>::Exp(xi.template segment<3>(3)),
              t.template cast<Scalar>());
}

template <typename Scalar>
typename Sim3<Scalar>::Tangent Sim3<Scalar>::Log() const {
  const Eigen::Vector3d omega = rotation_.Log().template cast<double>();
  const double sigma = std::log(static_cast<double>(scale_));
  const Eigen::Vector3d upsilon =
      SimilarityW(omega, sigma).partialPivLu().solve(translation_.template cast<double>());
  Eigen::Matrix<double, 7, 1> xi;
  xi << upsilon, omega, sigma;
  return xi.template cast<Scalar>();
}

template <typename Scalar>
Sim3<Scalar> Sim3<Scalar>::Inverse() const {
  const SO3<Scalar> R_inv = rotation_.Inverse();
  const Scalar s_inv = Scalar(1) / scale_;
  return Sim3(s_inv, R_inv, -s_inv * (R_inv * translation_));
}

template <typename Scalar>
Sim3<Scalar> Sim3<Scalar>::operator*(const Sim3& other) const {
  return Sim3(scale_ * other.scale_, rotation_ * other.rotation_,
              scale_ * (rotation_ * other.translation_) + translation_);
}

template <typename Scalar>
typename Sim3<Scalar>::Matrix4 Sim3<Scalar>::Matrix() const {
  Matrix4 S = Matrix4::Identity();
  S.template topLeftCorner<3, 3>() = scale_ * rotation_.Matrix();
  S.template topRightCorner<3, 1>() = translation_;
  return S;
}

template <typename Scalar>
typename Sim3<Scalar>::AdjointMatrix Sim3<Scalar>::Adjoint() const {
  const Matrix3 R = rotation_.Matrix();
  AdjointMatrix adj = AdjointMatrix::Zero();
  adj.template block<3, 3>(0, 0) = scale_ * R;
  adj.template block<3, 3>(0, 3) = SO3<Scalar>::Hat(translation_) * R;
  adj.template block<3, 1>(0, 6) = -translation_;
  adj.template block<3, 3>(3, 3) = R;
  adj(6, 6) = Scalar(1);
  return adj;
}

template <typename Scalar>
typename Sim3<Scalar>::Matrix4 Sim3<Scalar>::Hat(const Tangent& xi) {
  Matrix4 m = Matrix4::Zero();
  m.template topLeftCorner<3, 3>() =
      SO3<Scalar>::Hat(xi.template segment<3>(3)) + xi[6] * Matrix3::Identity();
  m.template topRightCorner<3, 1>() = xi.template head<3>();
  return m;
}

template <typename Scalar>
typename Sim3<Scalar>::Tangent Sim3<Scalar>::Vee(const Matrix4& m) {
  Tangent xi;
  xi.template head<3>() = m.template topRightCorner<3, 1>();
  const Matrix3 block = m.template topLeftCorner<3, 3>();
  xi.template segment<3>(3) = SO3<Scalar>::Vee(block);
  xi[6] = block.trace() / Scalar(3);
  return xi;
}

template <typename Scalar>
Eigen::Matrix<Scalar, 3, 7> Sim3<Scalar>::JacobianActionLeftPerturbation(const Vector3& p) const {
  const Vector3 q = *this * p;
  Eigen::Matrix<Scalar, 3, 7> J;
  J.template leftCols<3>().setIdentity();
  J.template block<3, 3>(0, 3) = -SO3<Scalar>::Hat(q);
  J.template rightCols<1>() = q;
  return J;
}

template class Sim3<float>;
template class Sim3<double>;

}  // namespace parallax
