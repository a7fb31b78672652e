#include "core/calibration_check.hpp"

#include <cmath>
#include <sstream>

namespace parallax {
namespace {

std::string Number(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

std::string IntrinsicsProblem(const PinholeCamera& K, const CalibrationLimits& limits) {
  const double w = K.Width(), h = K.Height();
  const double lo = limits.min_focal_per_width * w, hi = limits.max_focal_per_width * w;
  for (const auto& [name, f] : {std::pair{"fx", K.Fx()}, std::pair{"fy", K.Fy()}}) {
    if (!(f >= lo && f <= hi)) {
      return std::string(name) + " = " + Number(f) + " px is not a focal length for " + Number(w) +
             " px wide images (expected " + Number(lo) + " to " + Number(hi) + ")";
    }
  }
  const double aspect = K.Fx() / K.Fy();
  if (aspect > limits.max_aspect || aspect < 1.0 / limits.max_aspect) {
    return "fx / fy = " + Number(aspect) + " is not a pixel aspect ratio (expected 1/" +
           Number(limits.max_aspect) + " to " + Number(limits.max_aspect) + ")";
  }
  const double mx = limits.principal_point_margin * w, my = limits.principal_point_margin * h;
  if (K.Cx() < -mx || K.Cx() > w + mx || K.Cy() < -my || K.Cy() > h + my) {
    return "principal point (" + Number(K.Cx()) + ", " + Number(K.Cy()) + ") is outside the " +
           Number(w) + "x" + Number(h) + " image";
  }
  return {};
}

/// Every border pixel must undistort, and distort back to itself; along each ray from the
/// principal point the undistorted radius must grow (the model is one-to-one over the image).
std::string DistortionProblem(const Camera& camera, const CalibrationLimits& limits) {
  if (camera.Model() == CameraModel::kPinhole) return {};
  const PinholeCamera& K = camera.Intrinsics();
  const double w = K.Width() - 1.0, h = K.Height() - 1.0;
  const int n = limits.border_samples;
  for (int side = 0; side < 4; ++side) {
    for (int i = 0; i <= n; ++i) {
      const double a = static_cast<double>(i) / n;
      const Eigen::Vector2d border = side == 0   ? Eigen::Vector2d(a * w, 0.0)
                                     : side == 1 ? Eigen::Vector2d(a * w, h)
                                     : side == 2 ? Eigen::Vector2d(0.0, a * h)
                                                 : Eigen::Vector2d(w, a * h);
      const Eigen::Vector2d x_d((border.x() - K.Cx()) / K.Fx(), (border.y() - K.Cy()) / K.Fy());
      double previous = 0.0;
      for (int step = 1; step <= 16; ++step) {
        const Eigen::Vector2d sample = x_d * (step / 16.0);
        const auto x = camera.Undistort(sample);
        // Fisheye and FOV lenses see past 90 degrees in their (dark) corners, where no
        // pinhole ray exists: the ray ends there. Closer in, every pixel must invert.
        const bool wide =
            camera.Model() == CameraModel::kEquidistant || camera.Model() == CameraModel::kFov;
        if (!x && wide && sample.norm() >= limits.wide_angle_radius) break;
        if (!x || (camera.Distort(*x) - sample).norm() > 1e-6 * (1.0 + sample.norm())) {
          const Eigen::Vector2d pixel(K.Cx() + K.Fx() * sample.x(), K.Cy() + K.Fy() * sample.y());
          return "the distortion cannot be inverted at pixel (" + Number(pixel.x()) + ", " +
                 Number(pixel.y()) + ")";
        }
        if (!(x->norm() > previous)) {
          return "the distortion folds the image over itself (not monotonic towards pixel (" +
                 Number(border.x()) + ", " + Number(border.y()) + "))";
        }
        previous = x->norm();
      }
      const double ratio = previous / std::max(x_d.norm(), 1e-12);  // (wide lenses: unused)
      if (camera.Model() != CameraModel::kEquidistant && x_d.norm() > 0.05 &&
          (ratio > limits.max_radius_ratio || ratio < 1.0 / limits.max_radius_ratio)) {
        return "the distortion changes the radius at the image border by a factor of " +
               Number(ratio) + " (implausible coefficients)";
      }
    }
  }
  return {};
}

}  // namespace

std::string CalibrationProblem(const Camera& camera, const CalibrationLimits& limits) {
  std::string problem = IntrinsicsProblem(camera.Intrinsics(), limits);
  if (problem.empty()) problem = DistortionProblem(camera, limits);
  return problem;
}

}  // namespace parallax
