#pragma once
// Which pixels of a rectified camera's images see the scene (docs/calibration.md, "Validity
// mask"): a `full` undistortion leaves black where no input pixel reaches, and its border
// must never be taken for texture.

#include <vector>

#include "core/image.hpp"

namespace parallax {

/// Per pyramid level, 1 where a pixel and its gradient and interpolation stencils see only
/// valid input, 0 elsewhere. Immutable; shared by every frame of a camera.
class ValidityMask {
 public:
  /// `valid` has the camera's size; nonzero where the pixel's value comes from the input.
  /// Level l + 1 is valid where all four level-l pixels it averages are; every level is then
  /// eroded by `margin` pixels (>= 0), so that central-difference gradients, their 3x3
  /// maximum and bilinear lookups at a valid pixel read only valid pixels. Levels are built
  /// down to a size of 1 pixel. Throws std::invalid_argument for an empty image or a
  /// negative margin.
  explicit ValidityMask(const ImageU8& valid, int margin = 2);

  int NumLevels() const { return static_cast<int>(levels_.size()); }
  /// Precondition: 0 <= level < NumLevels(). Size: the level-0 size halved `level` times.
  const ImageU8& Level(int level) const { return levels_[static_cast<std::size_t>(level)]; }
  /// Share of level-0 pixels that are valid (after erosion), in [0, 1].
  double ValidFraction() const { return valid_fraction_; }
  /// True when every level-0 pixel of the input was valid (nothing to mask).
  bool AllValid() const { return all_valid_; }

 private:
  std::vector<ImageU8> levels_;
  double valid_fraction_ = 0.0;
  bool all_valid_ = false;
};

}  // namespace parallax
