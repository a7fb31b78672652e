#pragma once
// Whether a calibration is physically meaningful for its image size: focal lengths within
// what a lens can have, the principal point on the image, and a distortion model that stays
// invertible, monotonic and of plausible strength over the whole image
// (docs/calibration.md, "Plausibility").

#include <string>

#include "core/camera.hpp"

namespace parallax {

struct CalibrationLimits {
  /// Focal length per image width: 0.04 (about 170 degrees of horizontal field of view for a
  /// pinhole) to 60 (about 1 degree).
  double min_focal_per_width = 0.04;
  double max_focal_per_width = 60.0;
  /// fx / fy (pixel aspect ratio).
  double max_aspect = 2.0;
  /// How far the principal point may lie outside the image, as a share of its size.
  double principal_point_margin = 0.1;
  /// Undistorted over distorted radius at the image border (radial-tangential and FOV): a
  /// distortion that shrinks or stretches the field of view by more than this is a typo.
  double max_radius_ratio = 4.0;
  /// Fisheye and FOV models: distorted radius (normalised) beyond which a pixel may lie past
  /// 90 degrees and have no pinhole ray (about 57 degrees for a near-equidistant lens).
  double wide_angle_radius = 1.0;
  /// Border samples per image side for the invertibility check.
  int border_samples = 64;
};

/// Empty when plausible; otherwise the first problem, e.g. "fx = 1e+100 px is not a focal
/// length for 640 px wide images (expected 25.6 to 38400)".
std::string CalibrationProblem(const Camera& camera, const CalibrationLimits& limits = {});

}  // namespace parallax
