#include "core/se3.hpp"

#include <stdexcept>

#include "core/divergence.hpp"

namespace parallax {

template <typename Scalar>
SE3<Scalar>::SE3(const SO3<Scalar>& rotation, const Vector3& translation)
    : rotation_(rotation), translation_(translation) {
  if (!translation.allFinite()) {
    throw NumericalDivergence("SE3: translation must be finite");
  }
}

template <typename Scalar>
SE3<Scalar>::SE3(const Matrix4& T)
    : SE3(SO3<Scalar>(Matrix3(T.template topLeftCorner<3, 3>())),
          Vector3(T.template topRightCorner<3, 1>())) {
  const Eigen::Matrix<Scalar, 1, 4> last_row = T.template bottomRows<1>();
  if (!last_row.isApprox(Eigen::Matrix<Scalar, 1, 4>(0, 0, 0, 1))) {
    throw std::invalid_argument("SE3: last row of a homogeneous matrix must be (0 0 0 1)");
  }
}

template <typename Scalar>
SE3<Scalar> SE3<Scalar>::Exp(const Tangent& xi) {
  const Vector3 omega = xi.template tail<3>();
  const SO3<Scalar> R = SO3<Scalar>::Exp(omega);
  // t = J_l(omega) upsilon (the "V" matrix of SE(3) is the left Jacobian of SO(3)).
  const Vector3 t = SO3<Scalar>::LeftJacobian(omega) * xi.template head<3>();
  return SE3(R, t);
}

template <typename Scalar>
typename SE3<Scalar>::Tangent SE3<Scalar>::Log() const {
  const Vector3 omega = rotation_.Log();
  Tangent xi;
  xi.template head<3>() = SO3<Scalar>::LeftJacobianInverse(omega) * translation_;
  xi.template tail<3>() = omega;
  return xi;
}

template <typename Scalar>
SE3<Scalar> SE3<Scalar>::Inverse() const {
  const SO3<Scalar> R_inv = rotation_.Inverse();
  return SE3(R_inv, -(R_inv * translation_), Unchecked{});
}

template <typename Scalar>
typename SE3<Scalar>::Matrix4 SE3<Scalar>::Matrix() const {
  Matrix4 T = Matrix4::Identity();
  T.template topLeftCorner<3, 3>() = rotation_.Matrix();
  T.template topRightCorner<3, 1>() = translation_;
  return T;
}

template <typename Scalar>
typename SE3<Scalar>::AdjointMatrix SE3<Scalar>::Adjoint() const {
  const Matrix3 R = rotation_.Matrix();
  AdjointMatrix adj = AdjointMatrix::Zero();
  adj.template topLeftCorner<3, 3>() = R;
  adj.template topRightCorner<3, 3>() = SO3<Scalar>::Hat(translation_) * R;
  adj.template bottomRightCorner<3, 3>() = R;
  return adj;
}

template <typename Scalar>
typename SE3<Scalar>::Matrix4 SE3<Scalar>::Hat(const Tangent& xi) {
  Matrix4 m = Matrix4::Zero();
  m.template topLeftCorner<3, 3>() = SO3<Scalar>::Hat(xi.template tail<3>());
  m.template topRightCorner<3, 1>() = xi.template head<3>();
  return m;
}

template <typename Scalar>
typename SE3<Scalar>::Tangent SE3<Scalar>::Vee(const Matrix4& m) {
  Tangent xi;
  xi.template head<3>() = m.template topRightCorner<3, 1>();
  xi.template tail<3>() = SO3<Scalar>::Vee(m.template topLeftCorner<3, 3>());
  return xi;
}

template <typename Scalar>
Eigen::Matrix<Scalar, 3, 6> SE3<Scalar>::JacobianActionLeftPerturbation(const Vector3& p) const {
  Eigen::Matrix<Scalar, 3, 6> J;
  J.template leftCols<3>().setIdentity();
  J.template rightCols<3>() = -SO3<Scalar>::Hat(*this * p);
  return J;
}

template class SE3<float>;
template class SE3<double>;

}  // namespace parallax
