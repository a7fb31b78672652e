// ValidityMask: erosion and levels; what the pyramid and the frame-quality gate do with it.

#include "core/validity_mask.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "core/frame_quality.hpp"
#include "core/image_pyramid.hpp"

namespace parallax {
namespace {

int CountValid(const ImageU8& level) {
  return static_cast<int>(std::count(level.Data(), level.Data() + level.NumPixels(), 1));
}

TEST(ValidityMask, ErodesEachLevelAndHalvesDownToOnePixel) {
  ImageU8 valid(64, 48, 255);
  valid(30, 20) = 0;  // one pixel without input
  const ValidityMask mask(valid, 2);
  // 64x48, 32x24, 16x12, 8x6, 4x3, 2x1.
  ASSERT_EQ(mask.NumLevels(), 6);
  EXPECT_EQ(mask.Level(5).Width(), 2);
  EXPECT_EQ(mask.Level(5).Height(), 1);
  EXPECT_FALSE(mask.AllValid());
  // Level 0: the 5x5 block around it.
  EXPECT_EQ(CountValid(mask.Level(0)), 64 * 48 - 25);
  EXPECT_EQ(mask.Level(0)(28, 18), 0);
  EXPECT_EQ(mask.Level(0)(32, 22), 0);
  EXPECT_EQ(mask.Level(0)(33, 20), 1);
  // Level 1: its parent (15, 10), eroded: again 5x5.
  EXPECT_EQ(CountValid(mask.Level(1)), 32 * 24 - 25);
  EXPECT_EQ(mask.Level(1)(13, 8), 0);
  EXPECT_EQ(mask.Level(1)(18, 10), 1);
  EXPECT_NEAR(mask.ValidFraction(), 1.0 - 25.0 / (64 * 48), 1e-12);
}

TEST(ValidityMask, AllValidStaysAllValidAtTheImageEdge) {
  const ValidityMask mask(ImageU8(40, 30, 1), 2);
  EXPECT_TRUE(mask.AllValid());
  for (int l = 0; l < mask.NumLevels(); ++l) {
    EXPECT_EQ(CountValid(mask.Level(l)), mask.Level(l).Width() * mask.Level(l).Height());
  }
  EXPECT_THROW(ValidityMask(ImageU8(), 2), std::invalid_argument);
  EXPECT_THROW(ValidityMask(ImageU8(4, 4, 1), -1), std::invalid_argument);
}

// A textured image whose left 20 columns are black, as a `full` rectification's border.
ImageU8 BorderedTexture(ImageU8* valid) {
  ImageU8 image(64, 48);
  *valid = ImageU8(64, 48, 1);
  for (int y = 0; y < 48; ++y) {
    for (int x = 0; x < 64; ++x) {
      const bool seen = x >= 20;
      (*valid)(x, y) = seen ? 1 : 0;
      image(x, y) =
          seen ? static_cast<std::uint8_t>(100 + 40 * (((x / 6) + (y / 6)) % 2)) : std::uint8_t{0};
    }
  }
  return image;
}

TEST(ValidityMask, ThePyramidHasNoGradientWhereNoInputIs) {
  ImageU8 valid;
  const ImageU8 image = BorderedTexture(&valid);
  const ValidityMask mask(valid, 2);
  const ImagePyramid plain(image, {3, 8});
  const ImagePyramid masked(image, {3, 8}, &mask);
  EXPECT_EQ(plain.Level(0).valid, nullptr);
  for (int l = 0; l < masked.NumLevels(); ++l) {
    const PyramidLevel& level = masked.Level(l);
    ASSERT_EQ(level.valid, mask.Level(l).Data());
    for (std::size_t i = 0; i < level.dx.NumPixels(); ++i) {
      if (level.valid[i] == 0) {
        EXPECT_EQ(level.dx.Data()[i], 0.0f);
        EXPECT_EQ(level.dy.Data()[i], 0.0f);
      }
    }
  }
  // The border's edge (x = 19..20) is texture without the mask and is not with it.
  const auto at_border = [](const std::vector<int>& pixels) {
    return std::count_if(pixels.begin(), pixels.end(), [](int i) { return i % 64 < 22; });
  };
  EXPECT_GT(at_border(SelectSemiDensePixels(plain.Level(0), 20.0f)), 40);
  EXPECT_EQ(at_border(SelectSemiDensePixels(masked.Level(0), 20.0f)), 0);
  // The texture inside is still selected.
  EXPECT_GT(SelectSemiDensePixels(masked.Level(0), 20.0f).size(), 300u);
  EXPECT_THROW(ImagePyramid(ImageU8(32, 48, 1), {}, &mask), std::invalid_argument);
}

TEST(ValidityMask, NoiseInsideABlackBorderIsStillNoise) {
  std::mt19937 rng(7);
  std::uniform_int_distribution<int> grey(60, 200);
  ImageU8 image(160, 120), valid(160, 120, 1);
  for (int y = 0; y < 120; ++y) {
    for (int x = 0; x < 160; ++x) {
      const bool seen = (x - 80) * (x - 80) + (y - 60) * (y - 60) < 55 * 55;
      valid(x, y) = seen ? 1 : 0;
      image(x, y) = seen ? static_cast<std::uint8_t>(grey(rng)) : std::uint8_t{0};
    }
  }
  const ValidityMask mask(valid, 2);
  // The border correlates with itself: without the mask, the noise passes for a scene.
  EXPECT_TRUE(AssessFrame(image).Usable());
  EXPECT_EQ(AssessFrame(image, {}, &mask.Level(0)).usability, FrameUsability::kNoise);
  EXPECT_EQ(AssessFrame(image, {}, &ValidityMask(ImageU8(160, 120, 0), 0).Level(0)).usability,
            FrameUsability::kBlank);
}

}  // namespace
}  // namespace parallax
