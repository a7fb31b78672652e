#pragma once
// Camera models of real lenses: pinhole, radial-tangential, equidistant (fisheye) and FOV.
// Models and units: docs/conventions.md ("Camera models").

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "core/pinhole_camera.hpp"

namespace parallax {

enum class CameraModel {
  kPinhole,      ///< no distortion parameters
  kRadTan,       ///< k1 k2 p1 p2 k3 (OpenCV order)
  kEquidistant,  ///< k1 k2 k3 k4 (Kannala-Brandt / OpenCV fisheye)
  kFov,          ///< omega (field-of-view / ATAN model of Devernay-Faugeras), radians
};

/// Number of distortion parameters a model takes.
int NumDistortionParameters(CameraModel model);
/// "pinhole", "radtan", "equidistant", "fov".
std::string ToString(CameraModel model);
/// Inverse of ToString (also accepts "radial-tangential", "fisheye", "atan"); throws
/// std::invalid_argument for an unknown name.
CameraModel CameraModelFromString(const std::string& name);

/// A calibrated camera: intrinsics K (pixels) of the distorted image plus a distortion model
/// acting on normalised coordinates x = (X/Z, Y/Z): uv = K * Distort(x).
class Camera {
 public:
  /// Throws std::invalid_argument naming the bad value: wrong parameter count, non-finite
  /// values, non-positive size or focal length, FOV omega outside (0, pi).
  Camera(CameraModel model, int width, int height, double fx, double fy, double cx, double cy,
         std::vector<double> distortion = {});

  CameraModel Model() const { return model_; }
  int Width() const { return intrinsics_.Width(); }
  int Height() const { return intrinsics_.Height(); }
  /// K of the distorted image as a pinhole camera (ignores distortion).
  const PinholeCamera& Intrinsics() const { return intrinsics_; }
  const std::vector<double>& Distortion() const { return distortion_; }

  /// Pixel of a point in camera coordinates; nullopt if z <= 0 or the result is not finite.
  std::optional<Eigen::Vector2d> Project(const Eigen::Vector3d& p_c) const;
  /// Ray (z = 1) through a pixel; nullopt where the distortion cannot be inverted.
  std::optional<Eigen::Vector3d> Unproject(const Eigen::Vector2d& uv) const;

  /// Distortion on normalised coordinates (z = 1 plane).
  Eigen::Vector2d Distort(const Eigen::Vector2d& x) const;
  /// d Distort / d x (2x2), analytic.
  Eigen::Matrix2d DistortJacobian(const Eigen::Vector2d& x) const;
  /// Inverse of Distort by Newton's method; nullopt if it does not converge to 1e-10 or lands
  /// where the model folds over (det of the Jacobian <= 0).
  std::optional<Eigen::Vector2d> Undistort(const Eigen::Vector2d& x_distorted) const;

  std::string ToString() const;

 private:
  // Radial models (equidistant, FOV): distorted radius f(r) and its derivative f'(r).
  double RadialDistortion(double r) const;
  double RadialDistortionDerivative(double r) const;
  std::optional<double> InvertRadialDistortion(double r_distorted) const;

  CameraModel model_;
  PinholeCamera intrinsics_;
  std::vector<double> distortion_;
};

}  // namespace parallax
