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

TEST(Frame, RejectsMismatchedOrEmptyInput) {
  const PinholeCamera camera(640, 480, 500, 500, 319.5, 239.5);
  EXPECT_THROW(Frame(0, 0.0, camera, ImageU8(320, 240)), std::invalid_argument);
  EXPECT_THROW(Frame(0, 0.0, camera, ImageU8()), std::invalid_argument);
  EXPECT_THROW(Frame(0, NAN, camera, ImageU8(640, 480)), std::invalid_argument);
}

}  // namespace
}  // namespace parallax
