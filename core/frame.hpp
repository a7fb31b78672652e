#pragma once
// An input image prepared for tracking and mapping.

#include <cstdint>
#include <memory>
#include <mutex>

#include "core/image.hpp"
#include "core/image_pyramid.hpp"
#include "core/pinhole_camera.hpp"

namespace parallax {

/// One camera frame in the engine's ideal pinhole camera: id, timestamp and the intensity
/// pyramid with gradients. Immutable after construction, so it can be shared between
/// threads as std::shared_ptr<const Frame>.
class Frame {
 public:
  /// `image` must already be undistorted to `camera` (same size); `timestamp` in seconds as
  /// given by the input. Throws std::invalid_argument for an empty image, a size mismatch or a
  /// non-finite timestamp.
  Frame(std::int64_t id, double timestamp, const PinholeCamera& camera, const ImageU8& image,
        const PyramidOptions& pyramid_options = {});

  std::int64_t Id() const { return id_; }
  double Timestamp() const { return timestamp_; }
  /// The pyramid as built: its level 0 has no gradients (Level(0) has them).
  const ImagePyramid& Pyramid() const { return pyramid_; }
  int NumLevels() const { return pyramid_.NumLevels(); }
  /// A level with its gradients. Level 0's are computed on the first call (thread-safe):
  /// tracking starts at level 1, so only keyframes (and a tracker set to level 0) need them.
  const PyramidLevel& Level(int level) const {
    return level == 0 ? LevelZero() : pyramid_.Level(level);
  }
  /// A level's intensity and validity, without computing gradients: level 0's dx and dy are
  /// empty unless Level(0) was called. For what reads only intensities (the depth update's
  /// search in the new frame).
  const PyramidLevel& IntensityLevel(int level) const { return pyramid_.Level(level); }
  /// Camera of pyramid level `level` (see PinholeCamera::AtLevel).
  const PinholeCamera& Camera(int level = 0) const {
    return cameras_[static_cast<std::size_t>(level)];
  }
  /// MaxGradient3x3 of level 0 (grey levels / pixel), computed on the first call (keyframes
  /// need it for pixel selection, every depth map and tracking reference built on them; other
  /// frames never do) and thread-safe.
  const ImageF& MaxGradient() const;

 private:
  std::int64_t id_;
  double timestamp_;
  std::shared_ptr<const ValidityMask> validity_;  ///< before pyramid_: its levels view it
  ImagePyramid pyramid_;
  std::vector<PinholeCamera> cameras_;
  const PyramidLevel& LevelZero() const;
  mutable std::once_flag level_zero_once_;
  mutable FloatBufferPool::Buffer level_zero_gradients_;
  mutable PyramidLevel level_zero_;
  mutable std::once_flag max_gradient_once_;
  mutable ImageF max_gradient_;
};

}  // namespace parallax
