// Frame construction and validation.

#include "core/frame.hpp"

#include <gtest/gtest.h>

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

TEST(Frame, RejectsMismatchedOrEmptyInput) {
  const PinholeCamera camera(640, 480, 500, 500, 319.5, 239.5);
  EXPECT_THROW(Frame(0, 0.0, camera, ImageU8(320, 240)), std::invalid_argument);
  EXPECT_THROW(Frame(0, 0.0, camera, ImageU8()), std::invalid_argument);
  EXPECT_THROW(Frame(0, NAN, camera, ImageU8(640, 480)), std::invalid_argument);
}

}  // namespace
}  // namespace parallax
