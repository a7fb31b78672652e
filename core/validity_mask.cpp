#include "core/validity_mask.hpp"

#include <algorithm>

#include "core/check.hpp"

namespace parallax {
namespace {

// 0/1 copy of a level, then a square erosion by `margin` (separable: rows, then columns).
// Pixels within `margin` of the image edge stay as they are: the pyramid already keeps its
// stencils off the edge.
ImageU8 Eroded(const ImageU8& raw, int margin) {
  const int w = raw.Width();
  const int h = raw.Height();
  ImageU8 rows(w, h);
  for (int y = 0; y < h; ++y) {
    const std::uint8_t* src = raw.Row(y);
    std::uint8_t* dst = rows.Row(y);
    for (int x = 0; x < w; ++x) {
      std::uint8_t v = 1;
      for (int k = std::max(0, x - margin); k <= std::min(w - 1, x + margin) && v; ++k) {
        v = src[k] != 0 ? 1 : 0;
      }
      dst[x] = v;
    }
  }
  ImageU8 out(w, h);
  for (int y = 0; y < h; ++y) {
    std::uint8_t* dst = out.Row(y);
    for (int x = 0; x < w; ++x) {
      std::uint8_t v = 1;
      for (int k = std::max(0, y - margin); k <= std::min(h - 1, y + margin) && v; ++k) {
        v = rows.Row(k)[x];
      }
      dst[x] = v;
    }
  }
  return out;
}

// A coarse pixel is valid when the 2x2 block it averages is (odd trailing rows and columns
// are dropped, as in ImagePyramid).
ImageU8 Coarser(const ImageU8& fine) {
  ImageU8 coarse(fine.Width() / 2, fine.Height() / 2);
  for (int y = 0; y < coarse.Height(); ++y) {
    const std::uint8_t* r0 = fine.Row(2 * y);
    const std::uint8_t* r1 = fine.Row(2 * y + 1);
    std::uint8_t* dst = coarse.Row(y);
    for (int x = 0; x < coarse.Width(); ++x) {
      dst[x] = (r0[2 * x] && r0[2 * x + 1] && r1[2 * x] && r1[2 * x + 1]) ? 1 : 0;
    }
  }
  return coarse;
}

}  // namespace

ValidityMask::ValidityMask(const ImageU8& valid, int margin) {
  CheckArgument(!valid.Empty(), "ValidityMask: the mask image is empty");
  CheckArgument(margin >= 0, "ValidityMask: margin must be >= 0");
  all_valid_ = std::all_of(valid.Data(), valid.Data() + valid.NumPixels(),
                           [](std::uint8_t v) { return v != 0; });
  ImageU8 raw = valid;
  for (;;) {
    levels_.push_back(Eroded(raw, margin));
    if (raw.Width() < 2 || raw.Height() < 2) break;
    raw = Coarser(raw);
  }
  const ImageU8& level0 = levels_.front();
  const auto count = std::count(level0.Data(), level0.Data() + level0.NumPixels(), 1);
  valid_fraction_ = static_cast<double>(count) / static_cast<double>(level0.NumPixels());
}

}  // namespace parallax
