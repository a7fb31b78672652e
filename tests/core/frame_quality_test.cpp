// The frame-quality gate: scenes pass, frames without structure are named.

#include "core/frame_quality.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace parallax {
namespace {

ImageU8 Noise(int w, int h, int lo, int hi, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_int_distribution<int> u(lo, hi);
  ImageU8 img(w, h);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) img(x, y) = static_cast<std::uint8_t>(u(rng));
  }
  return img;
}

/// Smooth blobs and edges with mild noise: structure like a scene's.
ImageU8 Scene(int w, int h, double gain, double offset) {
  std::mt19937_64 rng(3);
  std::normal_distribution<double> n(0.0, 2.0);
  ImageU8 img(w, h);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const double v = 128 + 60 * std::sin(0.05 * x) * std::cos(0.07 * y) + (x > w / 2 ? 30 : 0);
      img(x, y) = static_cast<std::uint8_t>(std::clamp(gain * v + offset + n(rng), 0.0, 255.0));
    }
  }
  return img;
}

TEST(FrameQuality, ScenesAreUsable) {
  EXPECT_TRUE(AssessFrame(Scene(640, 480, 1.0, 0.0)).Usable());
  // Dim but textured (a dark room with the exposure up): still usable.
  EXPECT_TRUE(AssessFrame(Scene(640, 480, 0.15, 0.0)).Usable())
      << AssessFrame(Scene(640, 480, 0.15, 0.0)).Reason();
}

TEST(FrameQuality, FramesWithoutStructureAreNamed) {
  const auto reason = [](const ImageU8& img) { return AssessFrame(img).Reason(); };
  EXPECT_EQ(AssessFrame(Noise(640, 480, 0, 255, 1)).usability, FrameUsability::kNoise)
      << reason(Noise(640, 480, 0, 255, 1));
  EXPECT_EQ(AssessFrame(Noise(640, 480, 100, 140, 2)).usability, FrameUsability::kNoise);
  EXPECT_EQ(AssessFrame(ImageU8(640, 480, 0)).usability, FrameUsability::kBlank);
  EXPECT_EQ(AssessFrame(ImageU8(640, 480, 255)).usability, FrameUsability::kBlank);
  EXPECT_EQ(AssessFrame(Noise(640, 480, 0, 12, 3)).usability, FrameUsability::kDark)
      << reason(Noise(640, 480, 0, 12, 3));
  EXPECT_EQ(AssessFrame(Scene(640, 480, 1.0, 150.0)).usability, FrameUsability::kBlownOut)
      << reason(Scene(640, 480, 1.0, 150.0));
  EXPECT_EQ(AssessFrame(ImageU8(1, 1, 128)).usability, FrameUsability::kTooSmall);
  EXPECT_NE(reason(Noise(640, 480, 0, 255, 1)).find("noise"), std::string::npos);
}

}  // namespace
}  // namespace parallax
