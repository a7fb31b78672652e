#pragma once
// The ideal pinhole camera the engine works in (after undistortion).

#include <Eigen/Core>
#include <memory>
#include <string>

namespace parallax {

class ValidityMask;

/// Pinhole intrinsics of a width x height image: u = fx x/z + cx, v = fy y/z + cy, in pixels,
/// with pixel (0,0) centred on the top-left pixel (docs/conventions.md).
class PinholeCamera {
 public:
  /// Throws std::invalid_argument naming the bad parameter unless width, height > 0,
  /// fx, fy > 0 and all values finite.
  PinholeCamera(int width, int height, double fx, double fy, double cx, double cy);

  int Width() const { return width_; }
  int Height() const { return height_; }
  double Fx() const { return fx_; }
  double Fy() const { return fy_; }
  double Cx() const { return cx_; }
  double Cy() const { return cy_; }
  Eigen::Matrix3d K() const;

  /// Projects a point in camera coordinates. Precondition: p_c.z() > 0.
  Eigen::Vector2d Project(const Eigen::Vector3d& p_c) const {
    return {fx_ * p_c.x() / p_c.z() + cx_, fy_ * p_c.y() / p_c.z() + cy_};
  }
  /// d Project / d p_c (2x3). Precondition: p_c.z() > 0.
  Eigen::Matrix<double, 2, 3> ProjectJacobian(const Eigen::Vector3d& p_c) const;
  /// The ray through pixel uv, scaled to z = 1.
  Eigen::Vector3d Unproject(const Eigen::Vector2d& uv) const {
    return {(uv.x() - cx_) / fx_, (uv.y() - cy_) / fy_, 1.0};
  }
  bool IsInside(const Eigen::Vector2d& uv, double border = 0.0) const {
    return uv.x() >= border && uv.y() >= border && uv.x() <= width_ - 1 - border &&
           uv.y() <= height_ - 1 - border;
  }

  /// The camera of pyramid level `level` (each level halves the size by 2x2 averaging, odd
  /// trailing rows/columns dropped): f_l = f / 2^l, c_l = (c + 0.5) / 2^l - 0.5.
  PinholeCamera AtLevel(int level) const;

  std::string ToString() const;

  /// Which pixels see the scene (docs/calibration.md, "Validity mask"); nullptr: all of them.
  /// Set by the Undistorter when its view has pixels no input reaches. AtLevel's cameras
  /// have none: the mask of each level is ValidityMask::Level.
  const std::shared_ptr<const ValidityMask>& Validity() const { return validity_; }
  /// A copy that sees only the pixels of `mask` (level 0 must have this camera's size;
  /// throws std::invalid_argument otherwise). nullptr removes the mask.
  PinholeCamera WithValidity(std::shared_ptr<const ValidityMask> mask) const;

 private:
  int width_;
  int height_;
  double fx_;
  double fy_;
  double cx_;
  double cy_;
  std::shared_ptr<const ValidityMask> validity_;
};

}  // namespace parallax
