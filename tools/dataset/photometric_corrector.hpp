#pragma once
// Undoing a camera's response curve and vignette (TUM monoVO pcalib.txt and vignette.png)
// before undistortion (docs/datasets.md, "Photometric calibration").

#include <array>
#include <optional>

#include "core/image.hpp"
#include "tools/dataset/dataset_reader.hpp"

namespace parallax {

/// out(x) = G^-1(in(x)) * v_ref / V(x), rounded to 8 bits: intensities proportional to the
/// irradiance times the exposure. G^-1 is scaled so that G^-1(255) = 255; v_ref is the
/// smallest positive vignette value (at least `kMinVignette`), so that corrected pixels
/// stay within [0, 255] where the vignette is above it. Exposure times are not divided
/// out: after G^-1 an exposure change is a pure gain, which tracking's affine brightness
/// estimates frame to frame. Pixels whose vignette is 0 (outside the lens's image) become 0.
class PhotometricCorrector {
 public:
  /// Vignette values below this (of the maximum) are treated as outside the image.
  static constexpr float kMinVignette = 0.05f;

  /// `calibration` for images of `width` x `height`. Throws std::invalid_argument when the
  /// response is not 256 finite, non-decreasing values with G^-1(255) > G^-1(0), or the
  /// vignette has the wrong size or values that are negative or not finite.
  PhotometricCorrector(const PhotometricCalibration& calibration, int width, int height);

  /// True when there is anything to correct (a response or a vignette).
  bool Enabled() const { return has_response_ || gain_.has_value(); }
  /// `in` must have the calibrated size (std::invalid_argument otherwise).
  void Apply(const ImageU8& in, ImageU8* out) const;

 private:
  std::array<float, 256> response_{};
  bool has_response_ = false;
  std::optional<ImageF> gain_;  ///< v_ref / V(x), 0 outside the image
  int width_ = 0;
  int height_ = 0;
};

}  // namespace parallax
