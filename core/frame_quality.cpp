#include "core/frame_quality.hpp"

#include <cmath>
#include <sstream>

#include "core/check.hpp"

namespace parallax {

void FrameQualityOptions::Check() const {
  CheckOption(min_contrast >= 0.0, "FrameQualityOptions", "min_contrast", "must be >= 0");
  CheckOption(max_saturated > 0.0 && max_saturated <= 1.0, "FrameQualityOptions", "max_saturated",
              "must be in (0, 1]");
  CheckOption(min_neighbour_correlation <= 1.0, "FrameQualityOptions", "min_neighbour_correlation",
              "must be <= 1");
  CheckOption(min_size >= 1, "FrameQualityOptions", "min_size", "must be >= 1");
  CheckOption(step >= 1, "FrameQualityOptions", "step", "must be >= 1");
}

std::string FrameQuality::Reason() const {
  std::ostringstream s;
  s.precision(3);
  switch (usability) {
    case FrameUsability::kUsable:
      return "usable";
    case FrameUsability::kTooSmall:
      return "unusable frame: too small";
    case FrameUsability::kBlank:
      s << "unusable frame: blank (contrast " << contrast << " grey levels)";
      break;
    case FrameUsability::kDark:
      s << "unusable frame: dark (mean " << mean << ", contrast " << contrast << ")";
      break;
    case FrameUsability::kBlownOut:
      s << "unusable frame: blown out (" << 100.0 * saturated << "% saturated)";
      break;
    case FrameUsability::kNoise:
      s << "unusable frame: noise (adjacent-pixel correlation " << correlation << ")";
      break;
  }
  return s.str();
}

FrameQuality AssessFrame(const ImageU8& image, const FrameQualityOptions& options,
                         const ImageU8* valid) {
  CheckArgument(
      valid == nullptr || (valid->Width() == image.Width() && valid->Height() == image.Height()),
      "AssessFrame: the validity mask's size differs from the image's");
  FrameQuality q;
  if (image.Width() < options.min_size || image.Height() < options.min_size) {
    q.usability = FrameUsability::kTooSmall;
    return q;
  }
  // One pass: moments of I, and of the products with the right and lower neighbours.
  double n = 0, sum = 0, sum_sq = 0, saturated = 0, sum_h = 0, sum_v = 0;
  for (int y = 0; y + 1 < image.Height(); y += options.step) {
    const std::uint8_t* row = image.Row(y);
    const std::uint8_t* below = image.Row(y + 1);
    const std::uint8_t* seen = valid != nullptr ? valid->Row(y) : nullptr;
    for (int x = 0; x + 1 < image.Width(); x += options.step) {
      if (seen != nullptr && seen[x] == 0) continue;  // no input there (eroded: neighbours too)
      const double v = row[x];
      sum += v;
      sum_sq += v * v;
      sum_h += v * row[x + 1];
      sum_v += v * below[x];
      saturated += v >= 250.0;
      n += 1.0;
    }
  }
  if (n == 0.0) {  // nothing of the image sees the scene
    q.usability = FrameUsability::kBlank;
    return q;
  }
  q.mean = sum / n;
  const double variance = std::max(sum_sq / n - q.mean * q.mean, 0.0);
  q.contrast = std::sqrt(variance);
  q.saturated = saturated / n;
  // Neighbours have the same mean and variance to first order over a whole image.
  q.correlation = variance > 0.0 ? (0.5 * (sum_h + sum_v) / n - q.mean * q.mean) / variance : 1.0;
  if (q.contrast < options.min_contrast) {
    q.usability = FrameUsability::kBlank;
  } else if (q.mean < options.dark_mean && q.contrast < options.dark_max_contrast) {
    q.usability = FrameUsability::kDark;
  } else if (q.saturated > options.max_saturated) {
    q.usability = FrameUsability::kBlownOut;
  } else if (q.correlation < options.min_neighbour_correlation) {
    q.usability = FrameUsability::kNoise;
  }
  return q;
}

}  // namespace parallax
