#include "tools/dataset/photometric_corrector.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "core/check.hpp"

namespace parallax {
namespace {

std::array<float, 256> ScaledResponse(const std::vector<float>& inverse_response) {
  std::array<float, 256> r{};
  for (int i = 0; i < 256; ++i) r[static_cast<std::size_t>(i)] = static_cast<float>(i);
  if (inverse_response.empty()) return r;
  CheckArgument(inverse_response.size() == 256,
                "photometric calibration: the inverse response needs 256 values, got " +
                    std::to_string(inverse_response.size()));
  for (std::size_t i = 0; i < 256; ++i) {
    CheckArgument(
        std::isfinite(inverse_response[i]),
        "photometric calibration: inverse response value " + std::to_string(i) + " is not finite");
    CheckArgument(i == 0 || inverse_response[i] >= inverse_response[i - 1],
                  "photometric calibration: the inverse response decreases at value " +
                      std::to_string(i) + " (it must be non-decreasing)");
  }
  const float low = inverse_response.front(), high = inverse_response.back();
  CheckArgument(high > low, "photometric calibration: the inverse response is constant");
  // Scaled to [G^-1(0) / G^-1(255), 1] * 255: relative irradiance in grey levels.
  CheckArgument(low >= 0.0f, "photometric calibration: the inverse response is negative");
  for (std::size_t i = 0; i < 256; ++i) r[i] = 255.0f * inverse_response[i] / high;
  return r;
}

}  // namespace

PhotometricCorrector::PhotometricCorrector(const PhotometricCalibration& calibration, int width,
                                           int height)
    : response_(ScaledResponse(calibration.inverse_response)),
      has_response_(!calibration.inverse_response.empty()),
      width_(width),
      height_(height) {
  if (!calibration.vignette) return;
  const ImageF& v = *calibration.vignette;
  CheckArgument(v.Width() == width && v.Height() == height,
                "photometric calibration: the vignette is " + std::to_string(v.Width()) + "x" +
                    std::to_string(v.Height()) + ", the images " + std::to_string(width) + "x" +
                    std::to_string(height));
  float max_value = 0.0f;
  for (std::size_t i = 0; i < v.NumPixels(); ++i) {
    const float value = v.Data()[i];
    CheckArgument(std::isfinite(value) && value >= 0.0f,
                  "photometric calibration: vignette values must be finite and >= 0");
    max_value = std::max(max_value, value);
  }
  CheckArgument(max_value > 0.0f, "photometric calibration: the vignette is all zero");
  float reference = std::numeric_limits<float>::max();
  for (std::size_t i = 0; i < v.NumPixels(); ++i) {
    const float relative = v.Data()[i] / max_value;
    if (relative >= kMinVignette) reference = std::min(reference, relative);
  }
  gain_.emplace(width, height);
  for (std::size_t i = 0; i < v.NumPixels(); ++i) {
    const float relative = v.Data()[i] / max_value;
    gain_->Data()[i] = relative >= kMinVignette ? reference / relative : 0.0f;
  }
}

void PhotometricCorrector::Apply(const ImageU8& in, ImageU8* out) const {
  CheckArgument(in.Width() == width_ && in.Height() == height_,
                "PhotometricCorrector::Apply: the image size differs from the calibration's");
  if (out->Width() != width_ || out->Height() != height_) *out = ImageU8(width_, height_);
  const std::uint8_t* src = in.Data();
  std::uint8_t* dst = out->Data();
  const float* gain = gain_ ? gain_->Data() : nullptr;
  for (std::size_t i = 0; i < in.NumPixels(); ++i) {
    float value = response_[src[i]];
    if (gain) value *= gain[i];
    dst[i] = static_cast<std::uint8_t>(std::lround(std::min(value, 255.0f)));
  }
}

}  // namespace parallax
