// Image pyramid: level sizes, the pixel-centre convention, gradients, pixel selection.

#include "core/image_pyramid.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace parallax {
namespace {

// I(x, y) = c + a x + b y, exactly representable in 8 bits on a small image.
ImageU8 Ramp(int w, int h, double a, double b, double c) {
  ImageU8 image(w, h);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) image(x, y) = static_cast<std::uint8_t>(c + a * x + b * y);
  }
  return image;
}

ImageU8 Checkerboard(int w, int h, int cell) {
  ImageU8 image(w, h);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) image(x, y) = ((x / cell + y / cell) % 2) ? 200 : 50;
  }
  return image;
}

TEST(ImagePyramid, LevelSizesForCommonAndOddImages) {
  const ImagePyramid vga(ImageU8(640, 480));
  ASSERT_EQ(vga.NumLevels(), 5);
  EXPECT_EQ(vga.Level(4).Width(), 40);
  EXPECT_EQ(vga.Level(4).Height(), 30);
  const ImagePyramid kitti(ImageU8(1226, 370));
  ASSERT_EQ(kitti.NumLevels(), 5);
  EXPECT_EQ(kitti.Level(1).Width(), 613);
  EXPECT_EQ(kitti.Level(2).Width(), 306);  // odd 613 drops its last column
  EXPECT_EQ(kitti.Level(4).Height(), 23);
  const ImagePyramid tiny(ImageU8(31, 20));
  EXPECT_EQ(tiny.NumLevels(), 1);  // 15x10 would be below min_level_size
  EXPECT_EQ(NumPyramidLevels(641, 481, {}), 5);
}

TEST(ImagePyramid, RampValuesFollowPixelCentreConvention) {
  // Averaging is exact on linear functions, so level-l pixel u_l holds the ramp evaluated at
  // level-0 coordinate (u_l + 0.5) 2^l - 0.5.
  const double a = 1.0, b = 1.0, c = 10.0;
  const ImagePyramid pyramid(Ramp(96, 96, a, b, c), {5, 4});
  for (int l = 0; l < pyramid.NumLevels(); ++l) {
    const PyramidLevel& level = pyramid.Level(l);
    const double s = std::ldexp(1.0, l);
    for (const auto& [x, y] : {std::pair{0, 0}, std::pair{3, 5}, std::pair{level.Width() - 1, 2}}) {
      const double x0 = (x + 0.5) * s - 0.5;
      const double y0 = (y + 0.5) * s - 0.5;
      EXPECT_NEAR(level.intensity(x, y), c + a * x0 + b * y0, 1e-4) << "level " << l;
    }
  }
}

TEST(ImagePyramid, GradientsOfRampScaleWithLevel) {
  const double a = 1.0, b = 1.0;
  const ImagePyramid pyramid(Ramp(96, 96, a, b, 10.0), {5, 4});
  for (int l = 0; l < pyramid.NumLevels(); ++l) {
    const PyramidLevel& level = pyramid.Level(l);
    const double s = std::ldexp(1.0, l);  // one level-l pixel spans s level-0 pixels
    EXPECT_NEAR(level.dx(2, 3), a * s, 1e-5);
    EXPECT_NEAR(level.dy(2, 3), b * s, 1e-5);
    EXPECT_NEAR(level.GradSq(2, 3), (a * a + b * b) * s * s, 1e-5);
    EXPECT_EQ(level.dx(0, 3), 0.0f);  // border convention
    EXPECT_EQ(level.dy(2, level.Height() - 1), 0.0f);
  }
}

TEST(ImagePyramid, CheckerboardAveragesToGreyAtCellScale) {
  const ImagePyramid pyramid(Checkerboard(128, 96, 4), {5, 4});
  // Level 2 pixels cover exactly one 4x4 cell: values 50 or 200.
  const PyramidLevel& l2 = pyramid.Level(2);
  EXPECT_FLOAT_EQ(l2.intensity(0, 0), 50.0f);
  EXPECT_FLOAT_EQ(l2.intensity(1, 0), 200.0f);
  // Level 3 pixels cover 2x2 cells: the mean, 125.
  EXPECT_FLOAT_EQ(pyramid.Level(3).intensity(3, 3), 125.0f);
  EXPECT_FLOAT_EQ(pyramid.Level(3).GradSq(3, 3), 0.0f);
}

TEST(ImagePyramid, RejectsEmptyImageAndBadOptions) {
  EXPECT_THROW(ImagePyramid{ImageU8{}}, std::invalid_argument);
  EXPECT_THROW(ImagePyramid(ImageU8(64, 48), {0, 16}), std::invalid_argument);
  try {
    PyramidOptions options;
    options.min_level_size = 0;
    options.Check();
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("PyramidOptions.min_level_size"), std::string::npos);
  }
  EXPECT_THROW(ImageU8(-1, 5), std::invalid_argument);
}

TEST(SemiDenseSelection, SelectsBothSidesOfAnEdgeAndNothingOnFlat) {
  ImageU8 image(40, 30, 80);
  for (int y = 0; y < 30; ++y) {
    for (int x = 20; x < 40; ++x) image(x, y) = 160;
  }
  const ImagePyramid pyramid(image, {1, 16});
  const auto selected = SelectSemiDensePixels(pyramid.Level(0), 10.0f, 2);
  ASSERT_FALSE(selected.empty());
  for (const int index : selected) {
    const int x = index % 40;
    const int y = index / 40;
    // Gradient is at x = 19 and 20; the 3x3 max spreads it to 18..21.
    EXPECT_GE(x, 18);
    EXPECT_LE(x, 21);
    EXPECT_GE(y, 2);
    EXPECT_LT(y, 28);
  }
  EXPECT_EQ(selected.size(), 4u * 26u);
  EXPECT_TRUE(
      SelectSemiDensePixels(ImagePyramid(ImageU8(40, 30, 80), {1, 16}).Level(0), 1.0f).empty());
}

TEST(SemiDenseSelection, MaxGradientIsMaximumOverNeighbourhood) {
  const ImagePyramid pyramid(Checkerboard(64, 48, 8), {1, 16});
  const PyramidLevel& level = pyramid.Level(0);
  const ImageF max_grad = MaxGradient3x3(level);
  for (int y = 1; y < 47; y += 5) {
    for (int x = 1; x < 63; x += 3) {
      float expected = 0.0f;
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          expected = std::max(expected, std::sqrt(level.GradSq(x + dx, y + dy)));
        }
      }
      EXPECT_FLOAT_EQ(max_grad(x, y), expected);
    }
  }
}

TEST(SemiDenseSelection, MaxGradientIsExactlyTheLargestMagnitudeInTheClampedWindow) {
  // Every pixel, the border included (the window is clamped to the image there), on an
  // irregular texture, compared bit for bit with the definition.
  ImageU8 image(37, 23);
  std::uint32_t state = 12345u;
  for (int y = 0; y < 23; ++y) {
    for (int x = 0; x < 37; ++x) {
      state = state * 1664525u + 1013904223u;
      image(x, y) = static_cast<std::uint8_t>(state >> 24);
    }
  }
  const ImagePyramid pyramid(image, {1, 16});
  const PyramidLevel& level = pyramid.Level(0);
  const ImageF max_grad = MaxGradient3x3(level);
  for (int y = 0; y < 23; ++y) {
    for (int x = 0; x < 37; ++x) {
      float expected = 0.0f;
      for (int v = std::max(y - 1, 0); v <= std::min(y + 1, 22); ++v) {
        for (int u = std::max(x - 1, 0); u <= std::min(x + 1, 36); ++u) {
          expected = std::max(expected, std::sqrt(level.GradSq(u, v)));
        }
      }
      ASSERT_EQ(max_grad(x, y), expected) << x << ", " << y;
    }
  }
}

TEST(Image, BilinearInterpolationIsExactOnRamps) {
  ImageF image(8, 8);
  for (int y = 0; y < 8; ++y) {
    for (int x = 0; x < 8; ++x)
      image(x, y) = 2.0f * static_cast<float>(x) + 3.0f * static_cast<float>(y);
  }
  EXPECT_NEAR(InterpolateBilinear(image, 2.25f, 4.5f), 2.0f * 2.25f + 3.0f * 4.5f, 1e-5);
  EXPECT_NEAR(InterpolateBilinear(image, 0.0f, 0.0f), 0.0f, 1e-6);
}

}  // namespace
}  // namespace parallax
