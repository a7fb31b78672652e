#include "core/camera.hpp"

#include <Eigen/LU>
#include <cmath>
#include <numbers>

#include "core/check.hpp"

namespace parallax {

int NumDistortionParameters(CameraModel model) {
  switch (model) {
    case CameraModel::kPinhole:
      return 0;
    case CameraModel::kRadTan:
      return 5;
    case CameraModel::kEquidistant:
      return 4;
    case CameraModel::kFov:
      return 1;
  }
  return 0;
}

std::string ToString(CameraModel model) {
  switch (model) {
    case CameraModel::kPinhole:
      return "pinhole";
    case CameraModel::kRadTan:
      return "radtan";
    case CameraModel::kEquidistant:
      return "equidistant";
    case CameraModel::kFov:
      return "fov";
  }
  return "unknown";
}

CameraModel CameraModelFromString(const std::string& name) {
  if (name == "pinhole") return CameraModel::kPinhole;
  if (name == "radtan" || name == "radial-tangential") return CameraModel::kRadTan;
  if (name == "equidistant" || name == "fisheye") return CameraModel::kEquidistant;
  if (name == "fov" || name == "atan") return CameraModel::kFov;
  throw std::invalid_argument("unknown camera model '" + name +
                              "' (expected pinhole, radtan, equidistant or fov)");
}

Camera::Camera(CameraModel model, int width, int height, double fx, double fy, double cx, double cy,
               std::vector<double> distortion)
    : model_(model),
      intrinsics_(width, height, fx, fy, cx, cy),
      distortion_(std::move(distortion)) {
  const int expected = NumDistortionParameters(model);
  CheckArgument(static_cast<int>(distortion_.size()) == expected,
                "Camera: model " + parallax::ToString(model) + " takes " +
                    std::to_string(expected) + " distortion parameters, got " +
                    std::to_string(distortion_.size()));
  for (std::size_t i = 0; i < distortion_.size(); ++i) {
    CheckArgument(std::isfinite(distortion_[i]),
                  "Camera: distortion parameter " + std::to_string(i) + " is not finite");
  }
  if (model == CameraModel::kFov) {
    CheckArgument(
        distortion_[0] > 0.0 && distortion_[0] < std::numbers::pi,
        "Camera: FOV omega must be in (0, pi) radians, got " + std::to_string(distortion_[0]));
  }
}

std::optional<Eigen::Vector2d> Camera::Project(const Eigen::Vector3d& p_c) const {
  if (!(p_c.z() > 0.0)) return std::nullopt;
  const Eigen::Vector2d x_d = Distort(p_c.head<2>() / p_c.z());
  const Eigen::Vector2d uv(intrinsics_.Fx() * x_d.x() + intrinsics_.Cx(),
                           intrinsics_.Fy() * x_d.y() + intrinsics_.Cy());
  if (!uv.allFinite()) return std::nullopt;
  return uv;
}

std::optional<Eigen::Vector3d> Camera::Unproject(const Eigen::Vector2d& uv) const {
  const Eigen::Vector2d x_d((uv.x() - intrinsics_.Cx()) / intrinsics_.Fx(),
                            (uv.y() - intrinsics_.Cy()) / intrinsics_.Fy());
  const auto x = Undistort(x_d);
  if (!x) return std::nullopt;
  return Eigen::Vector3d(x->x(), x->y(), 1.0);
}

double Camera::RadialDistortion(double r) const {
  if (model_ == CameraModel::kFov) {
    const double omega = distortion_[0];
    return std::atan(2.0 * r * std::tan(0.5 * omega)) / omega;
  }
  // Equidistant: theta_d = theta (1 + k1 theta^2 + k2 theta^4 + k3 theta^6 + k4 theta^8).
  const double theta = std::atan(r);
  const double t2 = theta * theta;
  const auto& k = distortion_;
  return theta * (1.0 + t2 * (k[0] + t2 * (k[1] + t2 * (k[2] + t2 * k[3]))));
}

double Camera::RadialDistortionDerivative(double r) const {
  if (model_ == CameraModel::kFov) {
    const double omega = distortion_[0];
    const double c = 2.0 * std::tan(0.5 * omega);
    return c / (omega * (1.0 + c * c * r * r));
  }
  const double theta = std::atan(r);
  const double t2 = theta * theta;
  const auto& k = distortion_;
  const double dtheta_d =
      1.0 + t2 * (3.0 * k[0] + t2 * (5.0 * k[1] + t2 * (7.0 * k[2] + t2 * 9.0 * k[3])));
  return dtheta_d / (1.0 + r * r);
}

std::optional<double> Camera::InvertRadialDistortion(double r_d) const {
  if (model_ == CameraModel::kFov) {
    const double omega = distortion_[0];
    if (r_d * omega >= 0.5 * std::numbers::pi) return std::nullopt;
    return std::tan(r_d * omega) / (2.0 * std::tan(0.5 * omega));
  }
  // Equidistant: Newton on theta_d(theta) = r_d, then r = tan(theta).
  const auto& k = distortion_;
  double theta = r_d;
  for (int iteration = 0; iteration < 30; ++iteration) {
    const double t2 = theta * theta;
    const double f = theta * (1.0 + t2 * (k[0] + t2 * (k[1] + t2 * (k[2] + t2 * k[3])))) - r_d;
    const double df =
        1.0 + t2 * (3.0 * k[0] + t2 * (5.0 * k[1] + t2 * (7.0 * k[2] + t2 * 9.0 * k[3])));
    if (!(df > 0.0)) return std::nullopt;  // theta_d no longer monotonic
    const double step = f / df;
    theta -= step;
    if (std::abs(step) < 1e-14) break;
  }
  if (!(theta >= 0.0 && theta < 0.5 * std::numbers::pi)) return std::nullopt;
  return std::tan(theta);
}

Eigen::Vector2d Camera::Distort(const Eigen::Vector2d& x) const {
  switch (model_) {
    case CameraModel::kPinhole:
      return x;
    case CameraModel::kRadTan: {
      const auto& d = distortion_;
      const double xx = x.x() * x.x();
      const double yy = x.y() * x.y();
      const double xy = x.x() * x.y();
      const double r2 = xx + yy;
      const double radial = 1.0 + r2 * (d[0] + r2 * (d[1] + r2 * d[4]));
      return {x.x() * radial + 2.0 * d[2] * xy + d[3] * (r2 + 2.0 * xx),
              x.y() * radial + d[2] * (r2 + 2.0 * yy) + 2.0 * d[3] * xy};
    }
    case CameraModel::kEquidistant:
    case CameraModel::kFov: {
      const double r = x.norm();
      if (r < 1e-9) return RadialDistortionDerivative(0.0) * x;
      return (RadialDistortion(r) / r) * x;
    }
  }
  return x;
}

Eigen::Matrix2d Camera::DistortJacobian(const Eigen::Vector2d& x) const {
  switch (model_) {
    case CameraModel::kPinhole:
      return Eigen::Matrix2d::Identity();
    case CameraModel::kRadTan: {
      const auto& d = distortion_;
      const double r2 = x.squaredNorm();
      const double radial = 1.0 + r2 * (d[0] + r2 * (d[1] + r2 * d[4]));
      const double dradial_dr2 = d[0] + r2 * (2.0 * d[1] + 3.0 * r2 * d[4]);
      Eigen::Matrix2d J;
      J(0, 0) =
          radial + 2.0 * x.x() * x.x() * dradial_dr2 + 2.0 * d[2] * x.y() + 6.0 * d[3] * x.x();
      J(0, 1) = 2.0 * x.x() * x.y() * dradial_dr2 + 2.0 * d[2] * x.x() + 2.0 * d[3] * x.y();
      J(1, 0) = 2.0 * x.x() * x.y() * dradial_dr2 + 2.0 * d[2] * x.x() + 2.0 * d[3] * x.y();
      J(1, 1) =
          radial + 2.0 * x.y() * x.y() * dradial_dr2 + 6.0 * d[2] * x.y() + 2.0 * d[3] * x.x();
      return J;
    }
    case CameraModel::kEquidistant:
    case CameraModel::kFov: {
      // x_d = g(r) x with g = f(r)/r:  J = g I + (g'(r)/r) x x^T,  g' = (f' r - f) / r^2.
      const double r = x.norm();
      if (r < 1e-6) return RadialDistortionDerivative(0.0) * Eigen::Matrix2d::Identity();
      const double f = RadialDistortion(r);
      const double g = f / r;
      const double g_prime_over_r = (RadialDistortionDerivative(r) * r - f) / (r * r * r);
      return g * Eigen::Matrix2d::Identity() + g_prime_over_r * x * x.transpose();
    }
  }
  return Eigen::Matrix2d::Identity();
}

std::optional<Eigen::Vector2d> Camera::Undistort(const Eigen::Vector2d& x_d) const {
  if (!x_d.allFinite()) return std::nullopt;
  if (model_ == CameraModel::kPinhole) return x_d;
  if (model_ == CameraModel::kEquidistant || model_ == CameraModel::kFov) {
    const double r_d = x_d.norm();
    if (r_d < 1e-12) return x_d / RadialDistortionDerivative(0.0);
    const auto r = InvertRadialDistortion(r_d);
    if (!r) return std::nullopt;
    return (*r / r_d) * x_d;
  }
  // Radial-tangential: Newton's method in 2-D from x = x_d.
  Eigen::Vector2d x = x_d;
  for (int iteration = 0; iteration < 40; ++iteration) {
    const Eigen::Vector2d residual = Distort(x) - x_d;
    if (residual.norm() < 1e-12) break;
    const Eigen::Matrix2d J = DistortJacobian(x);
    if (!(J.determinant() > 1e-9)) return std::nullopt;
    x -= J.inverse() * residual;
    if (!x.allFinite()) return std::nullopt;
  }
  if ((Distort(x) - x_d).norm() > 1e-10 || !(DistortJacobian(x).determinant() > 0.0)) {
    return std::nullopt;
  }
  return x;
}

std::string Camera::ToString() const {
  // PinholeCamera::ToString starts with "pinhole "; replace that with the real model.
  std::string s = parallax::ToString(model_) + intrinsics_.ToString().substr(7);
  for (const double d : distortion_) s += " " + std::to_string(d);
  return s;
}

}  // namespace parallax
