#include "core/so3.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

#include "core/divergence.hpp"
#include "core/lie_coefficients.hpp"

namespace parallax {

template <typename Scalar>
SO3<Scalar>::SO3(const Quaternion& q) {
  const Scalar norm = q.norm();
  if (!std::isfinite(norm) || norm < Scalar(1e-6)) {
    throw NumericalDivergence("SO3: quaternion must be finite and non-zero, norm is " +
                              std::to_string(norm));
  }
  q_ = Quaternion(q.coeffs() / norm);
}

template <typename Scalar>
SO3<Scalar>::SO3(const Matrix3& R) {
  const double tolerance = sizeof(Scalar) == sizeof(float) ? 1e-4 : 1e-8;
  const Eigen::Matrix3d Rd = R.template cast<double>();
  const double orthogonality =
      (Rd.transpose() * Rd - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
  const double det = Rd.determinant();
  if (!std::isfinite(orthogonality) || !std::isfinite(det)) {
    throw NumericalDivergence("SO3: matrix is not finite");
  }
  if (orthogonality > tolerance || std::abs(det - 1.0) > tolerance) {
    throw std::invalid_argument(
        "SO3: matrix is not a rotation (max |R^T R - I| = " + std::to_string(orthogonality) +
        ", det = " + std::to_string(det) + ")");
  }
  q_ = Quaternion(R).normalized();
}

template <typename Scalar>
SO3<Scalar> SO3<Scalar>::Exp(const Tangent& omega) {
  const Eigen::Vector3d w = omega.template cast<double>();
  const double theta = w.norm();
  // sin(theta/2)/theta = 0.5 sinc(theta/2), finite at theta = 0.
  const double imag_factor = 0.5 * lie_detail::Sinc(0.5 * theta);
  const Eigen::Quaterniond q(std::cos(0.5 * theta), imag_factor * w.x(), imag_factor * w.y(),
                             imag_factor * w.z());
  return FromUnitQuaternion(q.normalized().template cast<Scalar>());
}

template <typename Scalar>
typename SO3<Scalar>::Tangent SO3<Scalar>::Log() const {
  Eigen::Quaterniond q = q_.template cast<double>();
  // q and -q are the same rotation; pick w >= 0 so the angle lies in [0, pi].
  if (q.w() < 0.0) q.coeffs() = -q.coeffs();
  const double vec_norm = q.vec().norm();
  double factor = 0.0;
  if (vec_norm < 1e-8) {
    // theta = 2 atan(n / w) ~= 2 n / w (1 - n^2 / (3 w^2)).
    factor = 2.0 / q.w() * (1.0 - vec_norm * vec_norm / (3.0 * q.w() * q.w()));
  } else {
    factor = 2.0 * std::atan2(vec_norm, q.w()) / vec_norm;  // stable near pi (w -> 0)
  }
  return (factor * q.vec()).template cast<Scalar>();
}

template <typename Scalar>
typename SO3<Scalar>::Matrix3 SO3<Scalar>::Hat(const Tangent& w) {
  Matrix3 m;
  m << Scalar(0), -w.z(), w.y(), w.z(), Scalar(0), -w.x(), -w.y(), w.x(), Scalar(0);
  return m;
}

template <typename Scalar>
typename SO3<Scalar>::Tangent SO3<Scalar>::Vee(const Matrix3& m) {
  return Tangent(m(2, 1), m(0, 2), m(1, 0));
}

template <typename Scalar>
typename SO3<Scalar>::Matrix3 SO3<Scalar>::LeftJacobian(const Tangent& omega) {
  const Eigen::Vector3d w = omega.template cast<double>();
  const double theta = w.norm();
  const Eigen::Matrix3d W = SO3<double>::Hat(w);
  const Eigen::Matrix3d J = Eigen::Matrix3d::Identity() + lie_detail::OneMinusCosOverSq(theta) * W +
                            lie_detail::ThetaMinusSinOverCube(theta) * W * W;
  return J.template cast<Scalar>();
}

template <typename Scalar>
typename SO3<Scalar>::Matrix3 SO3<Scalar>::LeftJacobianInverse(const Tangent& omega) {
  const Eigen::Vector3d w = omega.template cast<double>();
  const double theta = w.norm();
  const Eigen::Matrix3d W = SO3<double>::Hat(w);
  const Eigen::Matrix3d J_inv = Eigen::Matrix3d::Identity() - 0.5 * W +
                                lie_detail::LeftJacobianInverseCoefficient(theta) * W * W;
  return J_inv.template cast<Scalar>();
}

template class SO3<float>;
template class SO3<double>;

}  // namespace parallax
