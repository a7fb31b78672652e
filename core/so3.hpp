#pragma once
// Rotation group SO(3). Conventions: docs/conventions.md, math: docs/math/lie_groups.md.

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace parallax {

/// A 3-D rotation stored as a unit quaternion.
///
/// Invariant: | |q|^2 - 1 | stays at rounding level; every constructor and product
/// renormalises, so long compositions do not drift off the manifold.
/// Tangent vectors are rotation vectors omega (axis * angle, radians); perturbations are on
/// the left: R' = Exp(delta) * R.
template <typename Scalar>
class SO3 {
 public:
  static constexpr int kDoF = 3;
  using Vector3 = Eigen::Matrix<Scalar, 3, 1>;
  using Matrix3 = Eigen::Matrix<Scalar, 3, 3>;
  using Quaternion = Eigen::Quaternion<Scalar>;
  using Tangent = Vector3;

  /// Identity rotation.
  SO3() = default;
  /// From any non-zero finite quaternion (normalised here). Throws std::invalid_argument
  /// for a zero-norm or non-finite quaternion.
  explicit SO3(const Quaternion& q);
  /// From a rotation matrix. Throws std::invalid_argument unless R is orthonormal with
  /// det +1 to within 1e-4 (float) / 1e-8 (double) per entry.
  explicit SO3(const Matrix3& R);

  /// Exponential map: rotation by |omega| radians about omega / |omega|.
  static SO3 Exp(const Tangent& omega);
  /// Logarithm: the rotation vector with angle in [0, pi].
  Tangent Log() const;

  SO3 Inverse() const { return FromUnitQuaternion(q_.conjugate()); }
  SO3 operator*(const SO3& other) const { return SO3(q_ * other.q_); }
  SO3& operator*=(const SO3& other) { return *this = *this * other; }
  /// Rotates a point: R * p.
  Vector3 operator*(const Vector3& p) const { return q_ * p; }

  Matrix3 Matrix() const { return q_.toRotationMatrix(); }
  /// Adjoint: R * Exp(w) * R^-1 = Exp(Adjoint() * w); for SO(3) it is R itself.
  Matrix3 Adjoint() const { return Matrix(); }
  const Quaternion& UnitQuaternion() const { return q_; }

  /// Skew-symmetric matrix [w]_x with [w]_x p = w x p.
  static Matrix3 Hat(const Tangent& omega);
  /// Inverse of Hat (reads the off-diagonal entries; no check of skew-symmetry).
  static Tangent Vee(const Matrix3& omega_hat);

  /// Left Jacobian J_l(omega): Exp(omega + d) ~= Exp(J_l d) * Exp(omega) for small d.
  static Matrix3 LeftJacobian(const Tangent& omega);
  /// Inverse of the left Jacobian; defined for |omega| < 2 pi.
  static Matrix3 LeftJacobianInverse(const Tangent& omega);
  /// d/d(delta) of Exp(delta) * R * p at delta = 0: -[R p]_x (3x3).
  Matrix3 JacobianActionLeftPerturbation(const Vector3& p) const { return -Hat(*this * p); }

  template <typename Other>
  SO3<Other> Cast() const {
    return SO3<Other>::FromUnitQuaternion(q_.template cast<Other>().normalized());
  }

  /// Wraps a quaternion that the caller guarantees to be unit (no normalisation).
  static SO3 FromUnitQuaternion(const Quaternion& q) {
    SO3 r;
    r.q_ = q;
    return r;
  }

 private:
  Quaternion q_{Quaternion::Identity()};
};

extern template class SO3<float>;
extern template class SO3<double>;
using SO3f = SO3<float>;
using SO3d = SO3<double>;

}  // namespace parallax
