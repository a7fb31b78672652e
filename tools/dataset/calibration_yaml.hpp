#pragma once
// The Parallax camera calibration file (YAML), documented in docs/calibration.md.

#include <optional>
#include <string>

#include "core/camera.hpp"

namespace parallax {

/// Contents of a calibration file: the camera and an optional frame rate for image folders
/// and videos without timestamps.
struct CalibrationFile {
  Camera camera;
  std::optional<double> fps;
};

/// Reads a calibration YAML file:
///   model: radtan        # pinhole | radtan | equidistant | fov
///   width: 640           # pixels
///   height: 480
///   fx: 517.3            # pixels
///   fy: 516.5
///   cx: 318.6
///   cy: 255.3
///   distortion: [k1, k2, p1, p2, k3]   # count depends on the model; omit for pinhole
///   fps: 30              # optional
/// Throws InputError naming the file and line for a missing file, a YAML syntax error, a
/// missing or malformed key, or invalid values (fx = 0, NaN distortion, ...).
CalibrationFile ReadCalibrationYaml(const std::string& path);

/// Writes `camera` in the format above.
void WriteCalibrationYaml(const std::string& path, const Camera& camera,
                          std::optional<double> fps = std::nullopt);

}  // namespace parallax
