#include "core/pinhole_camera.hpp"

#include <cmath>
#include <utility>

#include "core/check.hpp"
#include "core/validity_mask.hpp"

namespace parallax {

PinholeCamera::PinholeCamera(int width, int height, double fx, double fy, double cx, double cy)
    : width_(width), height_(height), fx_(fx), fy_(fy), cx_(cx), cy_(cy) {
  CheckArgument(width > 0 && height > 0, "PinholeCamera: image size must be positive, got " +
                                             std::to_string(width) + "x" + std::to_string(height));
  CheckArgument(std::isfinite(fx) && fx > 0.0,
                "PinholeCamera: fx must be finite and > 0, got " + std::to_string(fx));
  CheckArgument(std::isfinite(fy) && fy > 0.0,
                "PinholeCamera: fy must be finite and > 0, got " + std::to_string(fy));
  CheckArgument(std::isfinite(cx), "PinholeCamera: cx must be finite");
  CheckArgument(std::isfinite(cy), "PinholeCamera: cy must be finite");
}

Eigen::Matrix3d PinholeCamera::K() const {
  Eigen::Matrix3d K;
  K << fx_, 0.0, cx_, 0.0, fy_, cy_, 0.0, 0.0, 1.0;
  return K;
}

Eigen::Matrix<double, 2, 3> PinholeCamera::ProjectJacobian(const Eigen::Vector3d& p_c) const {
  const double z_inv = 1.0 / p_c.z();
  Eigen::Matrix<double, 2, 3> J;
  J << fx_ * z_inv, 0.0, -fx_ * p_c.x() * z_inv * z_inv,  //
      0.0, fy_ * z_inv, -fy_ * p_c.y() * z_inv * z_inv;
  return J;
}

PinholeCamera PinholeCamera::AtLevel(int level) const {
  CheckArgument(level >= 0 && level < 31, "PinholeCamera::AtLevel: level must be in [0, 30]");
  const double scale = std::ldexp(1.0, -level);
  return PinholeCamera(std::max(1, width_ >> level), std::max(1, height_ >> level), fx_ * scale,
                       fy_ * scale, (cx_ + 0.5) * scale - 0.5, (cy_ + 0.5) * scale - 0.5);
}

PinholeCamera PinholeCamera::WithValidity(std::shared_ptr<const ValidityMask> mask) const {
  CheckArgument(
      mask == nullptr || (mask->Level(0).Width() == width_ && mask->Level(0).Height() == height_),
      "PinholeCamera::WithValidity: the mask's size differs from the camera's");
  PinholeCamera out = *this;
  out.validity_ = std::move(mask);
  return out;
}

std::string PinholeCamera::ToString() const {
  return "pinhole " + std::to_string(width_) + "x" + std::to_string(height_) +
         " fx=" + std::to_string(fx_) + " fy=" + std::to_string(fy_) +
         " cx=" + std::to_string(cx_) + " cy=" + std::to_string(cy_);
}

}  // namespace parallax
