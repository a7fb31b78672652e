// Undistorter: modes, identity, and undistort -> distort consistency on a rendered image.

#include "core/undistorter.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "core/validity_mask.hpp"

namespace parallax {
namespace {

Camera Fr1RadTan() {
  return Camera(CameraModel::kRadTan, 640, 480, 517.306408, 516.469215, 318.643040, 255.313989,
                {0.262383, -0.953104, -0.005358, 0.002628, 1.163314});
}

// A smooth pattern defined on the ideal (undistorted) normalised image plane.
double Pattern(double x, double y) {
  return 127.5 + 60.0 * std::sin(9.0 * x) * std::cos(7.0 * y) + 40.0 * std::sin(4.0 * x + 5.0 * y);
}

// Renders what the distorted camera sees of Pattern.
ImageU8 RenderDistorted(const Camera& camera) {
  ImageU8 image(camera.Width(), camera.Height());
  for (int v = 0; v < camera.Height(); ++v) {
    for (int u = 0; u < camera.Width(); ++u) {
      const auto ray = camera.Unproject(Eigen::Vector2d(u, v));
      const double value = ray ? Pattern(ray->x(), ray->y()) : 0.0;
      image(u, v) = static_cast<std::uint8_t>(std::lround(std::clamp(value, 0.0, 255.0)));
    }
  }
  return image;
}

TEST(Undistorter, PinholeInputIsIdentity) {
  const Camera camera(CameraModel::kPinhole, 64, 48, 50, 50, 31.5, 23.5);
  const Undistorter undistorter(camera, UndistorterOptions{});
  EXPECT_TRUE(undistorter.IsIdentity());
  ImageU8 image(64, 48);
  for (std::size_t i = 0; i < image.NumPixels(); ++i)
    image.Data()[i] = static_cast<std::uint8_t>(i);
  const ImageU8 out = undistorter.Apply(image);
  EXPECT_TRUE(std::equal(out.Data(), out.Data() + out.NumPixels(), image.Data()));
}

TEST(Undistorter, CropModeRecoversIdealImage) {
  const Camera camera = Fr1RadTan();
  const Undistorter undistorter(camera, UndistorterOptions{});
  const ImageU8 rectified = undistorter.Apply(RenderDistorted(camera));
  const PinholeCamera& K = undistorter.OutputCamera();
  double error_sum = 0.0;
  int count = 0;
  for (int v = 2; v < K.Height() - 2; ++v) {
    for (int u = 2; u < K.Width() - 2; ++u) {
      const Eigen::Vector3d ray = K.Unproject(Eigen::Vector2d(u, v));
      error_sum += std::abs(rectified(u, v) - Pattern(ray.x(), ray.y()));
      ++count;
    }
  }
  // Quantisation (0.25) plus bilinear interpolation of a smooth pattern.
  EXPECT_LT(error_sum / count, 1.0);
}

TEST(Undistorter, CropModeHasNoInvalidPixels) {
  const Undistorter undistorter(Fr1RadTan(), UndistorterOptions{});
  const PinholeCamera& K = undistorter.OutputCamera();
  for (int v = 0; v < K.Height(); v += 7) {
    for (int u = 0; u < K.Width(); u += 7) {
      const Eigen::Vector2f src = undistorter.SourceOf(u, v);
      EXPECT_GE(src.x(), 0.0f);
      EXPECT_GE(src.y(), 0.0f);
    }
  }
}

TEST(Undistorter, FullModeKeepsWholeInputInView) {
  const Camera camera = Fr1RadTan();
  UndistorterOptions options;
  options.mode = UndistortMode::kFull;
  const Undistorter undistorter(camera, options);
  const PinholeCamera& K = undistorter.OutputCamera();
  for (const Eigen::Vector2d& corner :
       {Eigen::Vector2d(0, 0), Eigen::Vector2d(639, 0), Eigen::Vector2d(0, 479),
        Eigen::Vector2d(639, 479), Eigen::Vector2d(320, 0), Eigen::Vector2d(0, 240)}) {
    const auto ray = camera.Unproject(corner);
    ASSERT_TRUE(ray.has_value());
    EXPECT_TRUE(K.IsInside(K.Project(*ray), -1e-6)) << corner.transpose();
  }
  // Full mode sees more than crop mode: smaller focal length.
  const Undistorter crop(camera, UndistorterOptions{});
  EXPECT_LT(K.Fx(), crop.OutputCamera().Fx());
}

TEST(Undistorter, FullModeMarksThePixelsNoInputReaches) {
  UndistorterOptions options;
  options.mode = UndistortMode::kFull;
  const Undistorter full(Fr1RadTan(), options);
  ASSERT_NE(full.OutputCamera().Validity(), nullptr);
  const ImageU8& valid = full.OutputCamera().Validity()->Level(0);
  const ImageU8 image = full.Apply(RenderDistorted(Fr1RadTan()));
  int black_border = 0;
  for (int v = 0; v < valid.Height(); ++v) {
    for (int u = 0; u < valid.Width(); ++u) {
      const bool no_input = full.SourceOf(u, v) == Eigen::Vector2f(-1.0f, -1.0f);
      if (no_input) {
        EXPECT_EQ(valid(u, v), 0) << u << "," << v;  // never valid
      }
      black_border += no_input && image(u, v) == 0;
    }
  }
  EXPECT_GT(black_border, 1000);  // the test is about something: there is a black border
  EXPECT_LT(full.OutputCamera().Validity()->ValidFraction(), 0.99);
  EXPECT_GT(full.OutputCamera().Validity()->ValidFraction(), 0.5);
  // Crop mode sees input everywhere: no mask.
  EXPECT_EQ(Undistorter(Fr1RadTan(), UndistorterOptions{}).OutputCamera().Validity(), nullptr);
}

TEST(Undistorter, ExplicitModeUsesGivenIntrinsics) {
  UndistorterOptions options;
  options.mode = UndistortMode::kExplicit;
  options.output_width = 320;
  options.output_height = 240;
  options.fx = options.fy = 250.0;
  options.cx = 159.5;
  options.cy = 119.5;
  const Undistorter undistorter(Fr1RadTan(), options);
  EXPECT_EQ(undistorter.OutputCamera().Width(), 320);
  EXPECT_DOUBLE_EQ(undistorter.OutputCamera().Fx(), 250.0);
  // The principal point maps to the input's principal point (distortion is 0 there).
  const Eigen::Vector2f src = undistorter.SourceOf(159, 119);
  EXPECT_NEAR(src.x(), 318.64 - 0.5 * 517.3 / 250.0, 0.05);
}

TEST(Undistorter, RejectsBadOptionsAndImages) {
  UndistorterOptions options;
  options.mode = UndistortMode::kExplicit;
  try {
    options.Check();
    FAIL() << "explicit mode without a size must be rejected";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("output_width"), std::string::npos);
  }
  const Undistorter undistorter(Fr1RadTan(), UndistorterOptions{});
  EXPECT_THROW(undistorter.Apply(ImageU8(320, 240)), std::invalid_argument);
  EXPECT_THROW(undistorter.Apply(ImageU8()), std::invalid_argument);
}

}  // namespace
}  // namespace parallax
