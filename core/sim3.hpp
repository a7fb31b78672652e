#pragma once
// Similarity transformations Sim(3). Conventions: docs/conventions.md; math:
// docs/math/lie_groups.md.

#include <Eigen/Core>

#include "core/se3.hpp"
#include "core/so3.hpp"

namespace parallax {

/// A similarity S_a_b = (s, R, t) mapping points of frame b into frame a: p_a = s R p_b + t.
///
/// Invariant: s is finite and > 0 (every constructor checks; divergent estimates cannot be
/// represented, so they are caught where they are produced).
/// Tangent vectors are (upsilon, omega, sigma) with s = exp(sigma); left perturbations.
template <typename Scalar>
class Sim3 {
 public:
  static constexpr int kDoF = 7;
  using Vector3 = Eigen::Matrix<Scalar, 3, 1>;
  using Matrix3 = Eigen::Matrix<Scalar, 3, 3>;
  using Matrix4 = Eigen::Matrix<Scalar, 4, 4>;
  using Tangent = Eigen::Matrix<Scalar, 7, 1>;
  using AdjointMatrix = Eigen::Matrix<Scalar, 7, 7>;

  /// Identity.
  Sim3() = default;
  /// Throws std::invalid_argument if scale <= 0 or anything is not finite.
  Sim3(Scalar scale, const SO3<Scalar>& rotation, const Vector3& translation);
  /// A rigid transformation with unit scale.
  explicit Sim3(const SE3<Scalar>& rigid);

  static Sim3 Exp(const Tangent& xi);
  Tangent Log() const;

  Sim3 Inverse() const;
  Sim3 operator*(const Sim3& other) const;
  Sim3& operator*=(const Sim3& other) { return *this = *this * other; }
  /// Transforms a point: s R p + t.
  Vector3 operator*(const Vector3& p) const { return scale_ * (rotation_ * p) + translation_; }

  Matrix4 Matrix() const;
  /// S * Exp(xi) * S^-1 = Exp(Adjoint() * xi); Adjoint = [sR, [t]_x R, -t; 0, R, 0; 0, 0, 1].
  AdjointMatrix Adjoint() const;

  Scalar Scale() const { return scale_; }
  const SO3<Scalar>& Rotation() const { return rotation_; }
  const Vector3& Translation() const { return translation_; }
  /// The rigid part (R, t), dropping the scale.
  SE3<Scalar> RigidPart() const { return SE3<Scalar>(rotation_, translation_); }

  /// 4x4 Lie algebra element [[omega]_x + sigma I, upsilon; 0, 0].
  static Matrix4 Hat(const Tangent& xi);
  static Tangent Vee(const Matrix4& xi_hat);

  /// d/d(delta) of Exp(delta) * S * p at delta = 0: [I, -[S p]_x, S p] (3x7).
  Eigen::Matrix<Scalar, 3, 7> JacobianActionLeftPerturbation(const Vector3& p) const;

  template <typename Other>
  Sim3<Other> Cast() const {
    return Sim3<Other>(static_cast<Other>(scale_), rotation_.template Cast<Other>(),
                       translation_.template cast<Other>());
  }

 private:
  Scalar scale_{1};
  SO3<Scalar> rotation_;
  Vector3 translation_{Vector3::Zero()};
};

extern template class Sim3<float>;
extern template class Sim3<double>;
using Sim3f = Sim3<float>;
using Sim3d = Sim3<double>;

}  // namespace parallax
