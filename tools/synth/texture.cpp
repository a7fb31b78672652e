#include "tools/synth/texture.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <opencv2/imgproc.hpp>

#include "core/check.hpp"
#include "tools/dataset/image_file.hpp"
#include "tools/dataset/input_error.hpp"
#include "tools/synth/random.hpp"

namespace parallax::synth {
namespace {

double Smooth(double t) { return t * t * (3.0 - 2.0 * t); }

// Value noise with `period` lattice cells across the tile (tileable), in [0, 1).
double ValueNoise(double u, double v, int period, std::uint64_t seed) {
  const double x = u * period;
  const double y = v * period;
  const auto x0 = static_cast<std::int64_t>(std::floor(x));
  const auto y0 = static_cast<std::int64_t>(std::floor(y));
  const double fx = Smooth(x - static_cast<double>(x0));
  const double fy = Smooth(y - static_cast<double>(y0));
  const auto wrap = [period](std::int64_t i) { return ((i % period) + period) % period; };
  const double a = HashToUnit(wrap(x0), wrap(y0), seed);
  const double b = HashToUnit(wrap(x0 + 1), wrap(y0), seed);
  const double c = HashToUnit(wrap(x0), wrap(y0 + 1), seed);
  const double d = HashToUnit(wrap(x0 + 1), wrap(y0 + 1), seed);
  return (1 - fy) * ((1 - fx) * a + fx * b) + fy * ((1 - fx) * c + fx * d);
}

// Fractal sum of octaves from `base_period` up to `max_period` cells, roughly in [-1, 1].
double Fbm(double u, double v, int base_period, int max_period, double gain, std::uint64_t seed) {
  double sum = 0.0, amplitude = 1.0, norm = 0.0;
  for (int period = base_period; period <= max_period; period *= 2) {
    sum += amplitude *
           (2.0 * ValueNoise(u, v, period, seed + static_cast<std::uint64_t>(period)) - 1.0);
    norm += amplitude;
    amplitude *= gain;
  }
  return sum / norm;
}

// Paints an axis-aligned rectangle (tile coordinates, wraps) with grey `value`.
void PaintRect(ImageF* image, double u0, double v0, double du, double dv, float value) {
  const int n = image->Width();
  const int x0 = static_cast<int>(u0 * n), y0 = static_cast<int>(v0 * n);
  const int w = std::max(1, static_cast<int>(du * n)), h = std::max(1, static_cast<int>(dv * n));
  for (int y = y0; y < y0 + h; ++y) {
    for (int x = x0; x < x0 + w; ++x) (*image)(((x % n) + n) % n, ((y % n) + n) % n) = value;
  }
}

void PaintDisc(ImageF* image, double uc, double vc, double radius, float value) {
  const int n = image->Width();
  const int r = std::max(1, static_cast<int>(radius * n));
  const int cx = static_cast<int>(uc * n), cy = static_cast<int>(vc * n);
  for (int y = -r; y <= r; ++y) {
    for (int x = -r; x <= r; ++x) {
      if (x * x + y * y <= r * r) (*image)(((cx + x) % n + n) % n, ((cy + y) % n + n) % n) = value;
    }
  }
}

float Clamp255(double v) { return static_cast<float>(std::clamp(v, 5.0, 250.0)); }

// Per-texel shading of the noise-based materials.
double ShadeTexel(Material material, double u, double v, int n, std::uint64_t seed) {
  const int fine = n / 2;
  switch (material) {
    case Material::kPlaster:
      return 140.0 + 55.0 * Fbm(u, v, 4, fine, 0.62, seed);
    case Material::kTiles: {
      const int tiles = 4;
      const double tu = u * tiles, tv = v * tiles;
      const double fu = tu - std::floor(tu), fv = tv - std::floor(tv);
      const bool grout = fu < 0.03 || fv < 0.03;
      const double shade =
          70.0 * HashToUnit(static_cast<std::int64_t>(tu), static_cast<std::int64_t>(tv), seed);
      return grout ? 60.0 : 120.0 + shade + 30.0 * Fbm(u, v, 16, fine, 0.6, seed);
    }
    case Material::kWood: {
      const double warp = 0.6 * Fbm(u, v, 2, 16, 0.5, seed);
      const double rings = std::sin(2.0 * std::numbers::pi * (6.0 * v + warp));
      return 120.0 + 45.0 * rings + 25.0 * Fbm(u, v, 8, fine, 0.65, seed + 7);
    }
    case Material::kBricks: {
      const int courses = 8;
      const double row = v * courses;
      const auto r = static_cast<std::int64_t>(row);
      const double col = u * courses / 2.0 + (r % 2 ? 0.5 : 0.0);
      const auto c = static_cast<std::int64_t>(col);
      const double fu = col - std::floor(col), fv = row - std::floor(row);
      if (fu < 0.04 || fv < 0.08) return 190.0 + 20.0 * Fbm(u, v, 32, fine, 0.6, seed);
      return 80.0 + 60.0 * HashToUnit(c % (courses / 2), r, seed) +
             25.0 * Fbm(u, v, 16, fine, 0.6, seed);
    }
    case Material::kAsphalt: {
      const double blotch = Fbm(u, v, 4, 16, 0.5, seed + 3) > 0.35 ? -40.0 : 0.0;
      return 100.0 + blotch + 35.0 * Fbm(u, v, 32, fine, 0.75, seed);
    }
    case Material::kPosters:
      return 150.0 + 30.0 * Fbm(u, v, 8, fine, 0.6, seed);
    case Material::kPrint:
      return 215.0 + 10.0 * Fbm(u, v, 16, fine, 0.6, seed);
  }
  return 128.0;
}

// Shapes painted over the base of the clutter-like materials.
void PaintShapes(Material material, ImageF* image, std::uint64_t seed) {
  Random rng(seed);
  if (material == Material::kPosters) {
    for (int i = 0; i < 90; ++i) {
      const float value = static_cast<float>(rng.Uniform(20.0, 240.0));
      // One draw per statement: function arguments are evaluated in an unspecified order
      // (g++ last first, clang first first), and the scene must not depend on the compiler.
      // Drawn last-first, as g++ drew them for every render measured so far.
      if (rng.Uniform() < 0.6) {
        const double dv = rng.Uniform(0.02, 0.2);
        const double du = rng.Uniform(0.02, 0.2);
        const double v0 = rng.Uniform();
        const double u0 = rng.Uniform();
        PaintRect(image, u0, v0, du, dv, value);
      } else {
        const double radius = rng.Uniform(0.01, 0.08);
        const double vc = rng.Uniform();
        const double uc = rng.Uniform();
        PaintDisc(image, uc, vc, radius, value);
      }
    }
  } else if (material == Material::kPrint) {
    for (double v = 0.05; v < 0.95; v += 0.045) {
      for (double u = 0.05; u < 0.95;) {
        const double w = rng.Uniform(0.008, 0.05);
        PaintRect(image, u, v, w, 0.018, static_cast<float>(rng.Uniform(20.0, 90.0)));
        u += w + rng.Uniform(0.006, 0.02);
      }
    }
  }
}

}  // namespace

Texture::Texture(ImageF base) {
  levels_.push_back(std::move(base));
  while (levels_.back().Width() > 1) {
    const ImageF& fine = levels_.back();
    ImageF coarse(fine.Width() / 2, fine.Height() / 2);
    for (int y = 0; y < coarse.Height(); ++y) {
      for (int x = 0; x < coarse.Width(); ++x) {
        coarse(x, y) = 0.25f * (fine(2 * x, 2 * y) + fine(2 * x + 1, 2 * y) +
                                fine(2 * x, 2 * y + 1) + fine(2 * x + 1, 2 * y + 1));
      }
    }
    levels_.push_back(std::move(coarse));
  }
}

Texture Texture::Procedural(Material material, int size, std::uint64_t seed) {
  CheckArgument(size >= 8 && (size & (size - 1)) == 0, "Texture size must be a power of two >= 8");
  ImageF image(size, size);
  for (int y = 0; y < size; ++y) {
    for (int x = 0; x < size; ++x) {
      image(x, y) = Clamp255(ShadeTexel(material, (x + 0.5) / size, (y + 0.5) / size, size, seed));
    }
  }
  PaintShapes(material, &image, seed ^ 0xABCDEFULL);
  return Texture(std::move(image));
}

Texture Texture::FromFile(const std::string& path) {
  const cv::Mat grey = ReadImageFile(path, ImageReadMode::kGrey8);
  int size = 8;
  while (size * 2 <= std::min({grey.cols, grey.rows, 1024})) size *= 2;
  cv::Mat resized;
  cv::resize(grey, resized, cv::Size(size, size), 0, 0, cv::INTER_AREA);
  ImageF image(size, size);
  for (int y = 0; y < size; ++y) {
    for (int x = 0; x < size; ++x) image(x, y) = static_cast<float>(resized.at<std::uint8_t>(y, x));
  }
  return Texture(std::move(image));
}

float Texture::SampleLevel(int level, float u, float v) const {
  // Precondition u, v >= 0 (quad texture coordinates and offsets are non-negative), so
  // truncation is floor; adding n keeps x, y positive after the half-texel shift.
  const ImageF& image = levels_[static_cast<std::size_t>(level)];
  const int n = image.Width();
  const int mask = n - 1;
  const float x = u * static_cast<float>(n) - 0.5f + static_cast<float>(n);
  const float y = v * static_cast<float>(n) - 0.5f + static_cast<float>(n);
  const int xi = static_cast<int>(x), yi = static_cast<int>(y);
  const float ax = x - static_cast<float>(xi), ay = y - static_cast<float>(yi);
  const int x0 = xi & mask, y0 = yi & mask, x1 = (xi + 1) & mask, y1 = (yi + 1) & mask;
  const float* r0 = image.Row(y0);
  const float* r1 = image.Row(y1);
  return (1 - ay) * ((1 - ax) * r0[x0] + ax * r0[x1]) + ay * ((1 - ax) * r1[x0] + ax * r1[x1]);
}

float Texture::Sample(float u, float v, float texels) const {
  // Level of detail log2(texels), linear in the mantissa: continuous and monotonic, which is
  // all trilinear blending needs, and much cheaper than log2f.
  int exponent = 0;
  const float mantissa = std::frexp(std::max(texels, 1.0f), &exponent);  // in [0.5, 1)
  const float lod = static_cast<float>(exponent - 1) + (2.0f * mantissa - 1.0f);
  const int max_level = NumLevels() - 1;
  const int l0 = std::min(static_cast<int>(lod), max_level);
  const float t = std::min(lod - static_cast<float>(l0), 1.0f);
  if (l0 >= max_level || t < 0.01f) return SampleLevel(l0, u, v);
  return (1 - t) * SampleLevel(l0, u, v) + t * SampleLevel(l0 + 1, u, v);
}

}  // namespace parallax::synth
