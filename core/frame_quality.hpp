#pragma once
// Whether an image carries structure a tracker can use: not blank, not dark or blown out,
// not sensor noise without a scene (docs/configuration.md, "Unusable frames").

#include <string>

#include "core/image.hpp"

namespace parallax {

struct FrameQualityOptions {
  /// Below this standard deviation of intensity (grey levels) a frame is blank (a covered
  /// lens, a black or white frame).
  double min_contrast = 2.5;
  /// Dark: mean below this and standard deviation below `dark_max_contrast`.
  double dark_mean = 12.0;
  double dark_max_contrast = 5.0;
  /// Blown out: more than this share of pixels at >= 250.
  double max_saturated = 0.7;
  /// Noise: correlation of horizontally and vertically adjacent pixels below this (white
  /// noise ~0; photographs and renders, blurred or not, 0.8 and more).
  double min_neighbour_correlation = 0.4;
  /// Frames smaller than this (either side, pixels) are unusable.
  int min_size = 32;
  /// Every `step`-th pixel in each direction is examined.
  int step = 2;

  void Check() const;
};

enum class FrameUsability { kUsable, kTooSmall, kBlank, kDark, kBlownOut, kNoise };

struct FrameQuality {
  FrameUsability usability = FrameUsability::kUsable;
  double mean = 0.0;         ///< grey levels
  double contrast = 0.0;     ///< standard deviation, grey levels
  double saturated = 0.0;    ///< share of pixels >= 250
  double correlation = 0.0;  ///< of adjacent pixels (mean of horizontal and vertical)
  bool Usable() const { return usability == FrameUsability::kUsable; }
  /// e.g. "unusable frame: noise (adjacent-pixel correlation 0.02)".
  std::string Reason() const;
};

/// `valid` (optional, the image's size): only its nonzero pixels are examined (a `full`
/// rectification's black border is neither contrast nor correlation); none: blank.
FrameQuality AssessFrame(const ImageU8& image, const FrameQualityOptions& options = {},
                         const ImageU8* valid = nullptr);

}  // namespace parallax
