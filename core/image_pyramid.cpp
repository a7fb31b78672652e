#include "core/image_pyramid.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <utility>
#include <vector>

#include "core/check.hpp"

namespace parallax {
namespace {

// Raw, writable plane inside the pyramid buffer (construction only).
struct Plane {
  float* data;
  int width;
  int height;
  float* Row(int y) const { return data + static_cast<std::ptrdiff_t>(y) * width; }
};

ImageViewF View(const Plane& p) { return ImageViewF(p.data, p.width, p.height); }

void ConvertToFloat(const ImageView<std::uint8_t>& image, const Plane& out) {
  const std::uint8_t* src = image.Data();
  const std::size_t n = image.NumPixels();
  for (std::size_t i = 0; i < n; ++i) out.data[i] = static_cast<float>(src[i]);
}

void Downsample2x2(const Plane& fine, const Plane& coarse) {
  for (int y = 0; y < coarse.height; ++y) {
    const float* r0 = fine.Row(2 * y);
    const float* r1 = fine.Row(2 * y + 1);
    float* dst = coarse.Row(y);
    for (int x = 0; x < coarse.width; ++x) {
      dst[x] = 0.25f * (r0[2 * x] + r0[2 * x + 1] + r1[2 * x] + r1[2 * x + 1]);
    }
  }
}

void ZeroRow(const Plane& plane, int y) { std::fill_n(plane.Row(y), plane.width, 0.0f); }

void ComputeGradients(const ImageViewF& I, const Plane& dx, const Plane& dy) {
  const int w = I.Width();
  const int h = I.Height();
  for (const Plane* p : {&dx, &dy}) {
    ZeroRow(*p, 0);
    ZeroRow(*p, h - 1);
  }
  for (int y = 1; y < h - 1; ++y) {
    const float* __restrict up = I.Row(y - 1);
    const float* __restrict mid = I.Row(y);
    const float* __restrict down = I.Row(y + 1);
    float* __restrict gx_row = dx.Row(y);
    float* __restrict gy_row = dy.Row(y);
    gx_row[0] = gy_row[0] = 0.0f;
    gx_row[w - 1] = gy_row[w - 1] = 0.0f;
    for (int x = 1; x < w - 1; ++x) {
      gx_row[x] = 0.5f * (mid[x + 1] - mid[x - 1]);
      gy_row[x] = 0.5f * (down[x] - up[x]);
    }
  }
}

// No texture where no input is: the border of the valid area is not an edge.
void ZeroInvalid(const std::uint8_t* valid, const Plane& dx, const Plane& dy) {
  const std::size_t n = static_cast<std::size_t>(dx.width) * static_cast<std::size_t>(dx.height);
  for (std::size_t i = 0; i < n; ++i) {
    if (valid[i] == 0) dx.data[i] = dy.data[i] = 0.0f;
  }
}

}  // namespace

void PyramidOptions::Check() const {
  CheckOption(max_levels >= 1 && max_levels <= 16, "PyramidOptions", "max_levels",
              "must be in [1, 16], got " + std::to_string(max_levels));
  CheckOption(min_level_size >= 2, "PyramidOptions", "min_level_size",
              "must be >= 2, got " + std::to_string(min_level_size));
}

int NumPyramidLevels(int width, int height, const PyramidOptions& options) {
  options.Check();
  int levels = 1;
  while (levels < options.max_levels && (width >> levels) >= options.min_level_size &&
         (height >> levels) >= options.min_level_size) {
    ++levels;
  }
  return levels;
}

ImagePyramid::ImagePyramid(const ImageView<std::uint8_t>& image, const PyramidOptions& options,
                           const ValidityMask* validity, LevelZeroGradients level_zero) {
  CheckArgument(!image.Empty(), "ImagePyramid: the input image is empty");
  CheckArgument(validity == nullptr || (validity->Level(0).Width() == image.Width() &&
                                        validity->Level(0).Height() == image.Height()),
                "ImagePyramid: the validity mask's size differs from the image's");
  const int num_levels = NumPyramidLevels(image.Width(), image.Height(), options);
  constexpr std::size_t kPlanes = 3;  // intensity, dx, dy
  const bool deferred = level_zero == LevelZeroGradients::kDeferred;
  const auto planes_of = [&](std::size_t l) { return deferred && l == 0 ? 1 : kPlanes; };
  std::vector<std::size_t> offsets;
  std::size_t total = 0;
  for (int l = 0; l < num_levels; ++l) {
    offsets.push_back(total);
    total += planes_of(static_cast<std::size_t>(l)) * static_cast<std::size_t>(image.Width() >> l) *
             static_cast<std::size_t>(image.Height() >> l);
  }
  // Every element is written below, so a recycled buffer needs no clearing.
  buffer_ = FloatBufferPool::Shared().Take(total);
  std::vector<std::array<Plane, kPlanes>> planes(static_cast<std::size_t>(num_levels));
  for (std::size_t l = 0; l < planes.size(); ++l) {
    const int w = image.Width() >> l;
    const int h = image.Height() >> l;
    const std::size_t n = static_cast<std::size_t>(w) * static_cast<std::size_t>(h);
    for (std::size_t p = 0; p < planes_of(l); ++p)
      planes[l][p] = Plane{buffer_.get() + offsets[l] + p * n, w, h};
  }
  ConvertToFloat(image, planes[0][0]);
  for (std::size_t l = 1; l < planes.size(); ++l) Downsample2x2(planes[l - 1][0], planes[l][0]);
  levels_.reserve(planes.size());
  const bool masked = validity != nullptr && !validity->AllValid();
  for (std::size_t l = 0; l < planes.size(); ++l) {
    const auto& level = planes[l];
    const std::uint8_t* valid = masked && static_cast<int>(l) < validity->NumLevels()
                                    ? validity->Level(static_cast<int>(l)).Data()
                                    : nullptr;
    if (planes_of(l) == 1) {
      levels_.push_back(PyramidLevel{View(level[0]), {}, {}, valid});
      continue;
    }
    ComputeGradients(View(level[0]), level[1], level[2]);
    if (valid != nullptr) ZeroInvalid(valid, level[1], level[2]);
    levels_.push_back(PyramidLevel{View(level[0]), View(level[1]), View(level[2]), valid});
  }
}

PyramidLevel ImagePyramid::LevelZeroWithGradients(FloatBufferPool::Buffer* storage) const {
  const PyramidLevel& zero = levels_.front();
  const int w = zero.Width(), h = zero.Height();
  const std::size_t n = static_cast<std::size_t>(w) * static_cast<std::size_t>(h);
  *storage = FloatBufferPool::Shared().Take(2 * n);
  const Plane dx{storage->get(), w, h}, dy{storage->get() + n, w, h};
  ComputeGradients(zero.intensity, dx, dy);
  if (zero.valid != nullptr) ZeroInvalid(zero.valid, dx, dy);
  return PyramidLevel{zero.intensity, View(dx), View(dy), zero.valid};
}

ImageF MaxGradient3x3(const PyramidLevel& level) {
  const int w = level.Width();
  const int h = level.Height();
  // One pass over the squared gradients, clamped at the border, without full-size
  // temporaries: their first touch of fresh memory was most of this function's cost
  // (docs/benchmarks.md, "Where a depth update and a keyframe spend their time"). sqrt is
  // monotonic and correctly rounded: the root of the largest square is the largest magnitude.
  ImageF out(w, h);
  // The squared gradients of rows y - 1, y and y + 1 (clamped), each computed once.
  std::array<std::vector<float>, 3> squares;
  for (auto& row : squares) row.resize(static_cast<std::size_t>(w));
  const auto square_row = [&](int y, std::vector<float>* row) {
    const float* gx = level.dx.Row(y);
    const float* gy = level.dy.Row(y);
    for (int x = 0; x < w; ++x) (*row)[static_cast<std::size_t>(x)] = gx[x] * gx[x] + gy[x] * gy[x];
  };
  square_row(0, &squares[1]);
  if (h > 1) square_row(1, &squares[2]);
  for (int y = 0; y < h; ++y) {
    // squares[0..2] hold rows y - 1, y, y + 1 (clamped to the image).
    if (y == 0) {
      squares[0] = squares[1];
      if (h == 1) squares[2] = squares[1];
    } else {
      std::swap(squares[0], squares[1]);
      std::swap(squares[1], squares[2]);
      if (y + 1 < h) {
        square_row(y + 1, &squares[2]);
      } else {
        squares[2] = squares[1];
      }
    }
    const std::array<const float*, 3> rows = {squares[0].data(), squares[1].data(),
                                              squares[2].data()};
    float* dst = out.Row(y);
    for (int x = 0; x < w; ++x) {
      const int left = std::max(x - 1, 0), right = std::min(x + 1, w - 1);
      float largest = 0.0f;
      for (const float* row : rows) largest = std::max({largest, row[left], row[x], row[right]});
      dst[x] = std::sqrt(largest);
    }
  }
  if (level.valid != nullptr) {  // the maximum must not spread back into the border
    for (std::size_t i = 0; i < out.NumPixels(); ++i) {
      if (level.valid[i] == 0) out.Data()[i] = 0.0f;
    }
  }
  return out;
}

std::vector<int> SelectSemiDensePixels(const PyramidLevel& level, float min_gradient, int border) {
  CheckArgument(border >= 0, "SelectSemiDensePixels: border must be >= 0");
  CheckArgument(std::isfinite(min_gradient), "SelectSemiDensePixels: min_gradient must be finite");
  const ImageF max_gradient = MaxGradient3x3(level);
  std::vector<int> indices;
  const int w = level.Width();
  for (int y = border; y < level.Height() - border; ++y) {
    const float* row = max_gradient.Row(y);
    for (int x = border; x < w - border; ++x) {
      if (row[x] >= min_gradient) indices.push_back(y * w + x);
    }
  }
  return indices;
}

}  // namespace parallax
