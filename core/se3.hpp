#pragma once
// Rigid-body transformations SE(3). Conventions: docs/conventions.md; math:
// docs/math/lie_groups.md.

#include <Eigen/Core>

#include "core/so3.hpp"

namespace parallax {

/// A rigid transformation T_a_b = (R, t) mapping points of frame b into frame a:
/// p_a = R p_b + t.
///
/// Tangent vectors are xi = (upsilon, omega): translation part first, rotation vector last.
/// Perturbations are on the left: T' = Exp(delta) * T.
template <typename Scalar>
class SE3 {
 public:
  static constexpr int kDoF = 6;
  using Vector3 = Eigen::Matrix<Scalar, 3, 1>;
  using Matrix3 = Eigen::Matrix<Scalar, 3, 3>;
  using Matrix4 = Eigen::Matrix<Scalar, 4, 4>;
  using Tangent = Eigen::Matrix<Scalar, 6, 1>;
  using AdjointMatrix = Eigen::Matrix<Scalar, 6, 6>;
  using Quaternion = Eigen::Quaternion<Scalar>;

  /// Identity transformation.
  SE3() = default;
  /// Throws std::invalid_argument if the translation is not finite.
  SE3(const SO3<Scalar>& rotation, const Vector3& translation);
  /// From a homogeneous 4x4 matrix; the rotation block must be a rotation (see SO3) and the
  /// last row (0 0 0 1).
  explicit SE3(const Matrix4& T);

  static SE3 Exp(const Tangent& xi);
  Tangent Log() const;

  SE3 Inverse() const;
  SE3 operator*(const SE3& other) const {
    return SE3(rotation_ * other.rotation_, rotation_ * other.translation_ + translation_,
               Unchecked{});
  }
  SE3& operator*=(const SE3& other) { return *this = *this * other; }
  /// Transforms a point: R p + t.
  Vector3 operator*(const Vector3& p) const { return rotation_ * p + translation_; }

  Matrix4 Matrix() const;
  /// T * Exp(xi) * T^-1 = Exp(Adjoint() * xi); Adjoint = [R, [t]_x R; 0, R].
  AdjointMatrix Adjoint() const;

  const SO3<Scalar>& Rotation() const { return rotation_; }
  const Vector3& Translation() const { return translation_; }
  Matrix3 RotationMatrix() const { return rotation_.Matrix(); }

  /// 4x4 matrix of the Lie algebra element: [[omega]_x, upsilon; 0, 0].
  static Matrix4 Hat(const Tangent& xi);
  static Tangent Vee(const Matrix4& xi_hat);

  /// d/d(delta) of Exp(delta) * T * p at delta = 0: [I, -[T p]_x] (3x6).
  Eigen::Matrix<Scalar, 3, 6> JacobianActionLeftPerturbation(const Vector3& p) const;

  template <typename Other>
  SE3<Other> Cast() const {
    return SE3<Other>(rotation_.template Cast<Other>(), translation_.template cast<Other>());
  }

 private:
  struct Unchecked {};
  SE3(const SO3<Scalar>& rotation, const Vector3& translation, Unchecked)
      : rotation_(rotation), translation_(translation) {}

  SO3<Scalar> rotation_;
  Vector3 translation_{Vector3::Zero()};
};

extern template class SE3<float>;
extern template class SE3<double>;
using SE3f = SE3<float>;
using SE3d = SE3<double>;

}  // namespace parallax
