// Frame construction and validation.

#include "core/frame.hpp"

#include <gtest/gtest.h>

#include <thread>
#include <vector>

#include "core/validity_mask.hpp"

namespace parallax {
namespace {

TEST(Frame, BuildsPyramidAndLevelCameras) {
  const PinholeCamera camera(640, 480, 500, 500, 319.5, 239.5);
  const Frame frame(7, 1305031102.175304, camera, ImageU8(640, 480, 128));
  EXPECT_EQ(frame.Id(), 7);
  EXPECT_DOUBLE_EQ(frame.Timestamp(), 1305031102.175304);
  ASSERT_EQ(frame.NumLevels(), 5);
  for (int level = 0; level < frame.NumLevels(); ++level) {
    EXPECT_EQ(frame.Camera(level).Width(), frame.Level(level).Width());
    EXPECT_EQ(frame.Camera(level).Height(), frame.Level(level).Height());
    EXPECT_DOUBLE_EQ(frame.Camera(level).Fx(), camera.AtLevel(level).Fx());
  }
}

TEST(Frame, MaxGradientIsComputedOnceAndMatchesTheFilter) {
  const PinholeCamera camera(64, 48, 50, 50, 31.5, 23.5);
  ImageU8 image(64, 48, 0);
  for (int y = 0; y < 48; ++y) {
    for (int x = 0; x < 64; ++x) image(x, y) = static_cast<std::uint8_t>((x * 7 + y * y) % 251);
  }
  const Frame frame(0, 0.0, camera, image);
  const ImageF& first = frame.MaxGradient();
  const ImageF expected = MaxGradient3x3(frame.Level(0));
  ASSERT_EQ(first.Width(), expected.Width());
  ASSERT_EQ(first.Height(), expected.Height());
  for (std::size_t i = 0; i < expected.NumPixels(); ++i)
    ASSERT_EQ(first.Data()[i], expected.Data()[i]) << i;
  EXPECT_EQ(&frame.MaxGradient(), &first);  // cached, not recomputed
}

// Level 0's gradients are computed on the first Level(0) call, from any thread, and are
// exactly those of a pyramid built with them (validity mask included).
TEST(Frame, LevelZeroGradientsAreComputedOnFirstUseExactlyAsThePyramidWould) {
  ImageU8 image(96, 64, 0), valid(96, 64, 255);
  for (int y = 0; y < 64; ++y) {
    for (int x = 0; x < 96; ++x) {
      image(x, y) = static_cast<std::uint8_t>((x * 13 + y * y * 3) % 241);
      if (x < 10 || y > 55) valid(x, y) = 0;
    }
  }
  const auto mask = std::make_shared<const ValidityMask>(valid, 3);
  const PinholeCamera camera = PinholeCamera(96, 64, 80, 80, 47.5, 31.5).WithValidity(mask);
  const Frame frame(0, 0.0, camera, image);
  EXPECT_TRUE(frame.IntensityLevel(0).dx.Empty());  // not computed until asked for
  EXPECT_EQ(frame.IntensityLevel(0).valid, mask->Level(0).Data());
  std::vector<const PyramidLevel*> seen(4);
  std::vector<std::thread> threads;
  for (std::size_t t = 0; t < seen.size(); ++t)
    threads.emplace_back([&, t] { seen[t] = &frame.Level(0); });
  for (auto& thread : threads) thread.join();
  for (const PyramidLevel* level : seen) EXPECT_EQ(level, seen[0]);  // computed once

  const ImagePyramid full(image, {}, mask.get());
  const PyramidLevel& lazy = frame.Level(0);
  const PyramidLevel& expected = full.Level(0);
  EXPECT_EQ(lazy.valid, expected.valid);
  EXPECT_EQ(lazy.intensity.Data(), frame.IntensityLevel(0).intensity.Data());
  for (const auto& [a, b] : {std::pair{lazy.dx, expected.dx}, std::pair{lazy.dy, expected.dy},
                             std::pair{lazy.intensity, expected.intensity}}) {
    ASSERT_EQ(a.Width(), b.Width());
    ASSERT_EQ(a.Height(), b.Height());
    for (std::size_t i = 0; i < b.NumPixels(); ++i) ASSERT_EQ(a.Data()[i], b.Data()[i]) << i;
  }
  EXPECT_EQ(lazy.dx(5, 20), 0.0f);  // masked
  EXPECT_NE(lazy.dx(40, 20), 0.0f);
  // The other levels were built with their gradients.
  for (int l = 1; l < frame.NumLevels(); ++l) {
    for (std::size_t i = 0; i < full.Level(l).dy.NumPixels(); ++i)
      ASSERT_EQ(frame.Level(l).dy.Data()[i], full.Level(l).dy.Data()[i]) << l << " " << i;
  }
}

TEST(Frame, RejectsMismatchedOrEmptyInput) {
  const PinholeCamera camera(640, 480, 500, 500, 319.5, 239.5);
  EXPECT_THROW(Frame(0, 0.0, camera, ImageU8(320, 240)), std::invalid_argument);
  EXPECT_THROW(Frame(0, 0.0, camera, ImageU8()), std::invalid_argument);
  EXPECT_THROW(Frame(0, NAN, camera, ImageU8(640, 480)), std::invalid_argument);
}

}  // namespace
}  // namespace parallax
