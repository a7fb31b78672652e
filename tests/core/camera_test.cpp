// Camera models: projection round trips, Jacobians, pyramid-level cameras, invalid input.

#include "core/camera.hpp"

#include <gtest/gtest.h>

#include "core/pinhole_camera.hpp"
#include "tests/core/lie_test_utils.hpp"

namespace parallax {
namespace {

using test::NumericJacobian;

// The freiburg1 colour camera (shared/data/README.md) and typical fisheye / FOV lenses.
Camera Fr1RadTan() {
  return Camera(CameraModel::kRadTan, 640, 480, 517.306408, 516.469215, 318.643040, 255.313989,
                {0.262383, -0.953104, -0.005358, 0.002628, 1.163314});
}
Camera Fisheye() {
  // Equidistant lens whose whole image stays within 90 degrees of the axis (r_d < 1.3 rad).
  return Camera(CameraModel::kEquidistant, 752, 480, 350.2, 350.4, 375.1, 240.3,
                {0.0034823, 0.000715, -0.0020532, 0.0002029});
}
Camera Fov() { return Camera(CameraModel::kFov, 640, 480, 277.3, 291.4, 312.2, 239.8, {0.9}); }

class CameraModelTest : public ::testing::TestWithParam<int> {
 protected:
  Camera MakeCamera() const {
    switch (GetParam()) {
      case 0:
        return Camera(CameraModel::kPinhole, 640, 480, 500, 510, 319.5, 239.5);
      case 1:
        return Fr1RadTan();
      case 2:
        return Fisheye();
      default:
        return Fov();
    }
  }
};

TEST_P(CameraModelTest, UnprojectProjectRoundTripOverImage) {
  const Camera camera = MakeCamera();
  int checked = 0;
  for (int v = 0; v < camera.Height(); v += 16) {
    for (int u = 0; u < camera.Width(); u += 16) {
      const Eigen::Vector2d uv(u, v);
      const auto ray = camera.Unproject(uv);
      if (!ray) continue;  // outside the model's invertible region
      ++checked;
      for (const double depth : {0.3, 2.0, 50.0}) {
        const auto back = camera.Project(*ray * depth);
        ASSERT_TRUE(back.has_value());
        EXPECT_LT((*back - uv).norm(), 1e-6) << camera.ToString() << " at " << u << "," << v;
      }
    }
  }
  // The whole image must be invertible for these lenses except perhaps extreme corners.
  const int grid_points = (camera.Width() / 16) * (camera.Height() / 16);
  EXPECT_GT(checked, 0.95 * grid_points);
}

TEST_P(CameraModelTest, DistortJacobianMatchesNumeric) {
  const Camera camera = MakeCamera();
  for (const Eigen::Vector2d& x : {Eigen::Vector2d(0, 0), Eigen::Vector2d(1e-7, -2e-7),
                                   Eigen::Vector2d(0.2, -0.1), Eigen::Vector2d(-0.5, 0.4)}) {
    const Eigen::Matrix2d numeric =
        NumericJacobian<2, 2>([&](const Eigen::Vector2d& p) { return camera.Distort(p); }, x, 1e-7);
    EXPECT_LT((camera.DistortJacobian(x) - numeric).norm(), 1e-6)
        << camera.ToString() << " at " << x.transpose();
  }
}

TEST_P(CameraModelTest, RejectsPointsBehindCamera) {
  const Camera camera = MakeCamera();
  EXPECT_FALSE(camera.Project(Eigen::Vector3d(0.1, 0.1, -1.0)).has_value());
  EXPECT_FALSE(camera.Project(Eigen::Vector3d(0.1, 0.1, 0.0)).has_value());
}

INSTANTIATE_TEST_SUITE_P(AllModels, CameraModelTest, ::testing::Values(0, 1, 2, 3));

TEST(PinholeCamera, ProjectJacobianMatchesNumeric) {
  const PinholeCamera camera(640, 480, 500, 510, 320, 240);
  const Eigen::Vector3d p(0.3, -0.2, 1.7);
  const auto numeric =
      NumericJacobian<2, 3>([&](const Eigen::Vector3d& q) { return camera.Project(q); }, p);
  EXPECT_LT((camera.ProjectJacobian(p) - numeric).norm(), 1e-6);
}

TEST(PinholeCamera, LevelCameraFollowsPixelCentreConvention) {
  // A level-l pixel centre u_l sits at level-0 coordinate (u_l + 0.5) 2^l - 0.5.
  const PinholeCamera camera(640, 480, 517.3, 516.5, 318.6, 255.3);
  const Eigen::Vector3d p(0.21, -0.13, 1.9);
  const Eigen::Vector2d uv0 = camera.Project(p);
  for (int level = 1; level < 5; ++level) {
    const PinholeCamera cl = camera.AtLevel(level);
    const double s = std::ldexp(1.0, level);
    const Eigen::Vector2d uvl = cl.Project(p);
    EXPECT_NEAR((uvl.x() + 0.5) * s - 0.5, uv0.x(), 1e-9);
    EXPECT_NEAR((uvl.y() + 0.5) * s - 0.5, uv0.y(), 1e-9);
    EXPECT_EQ(cl.Width(), 640 >> level);
  }
}

TEST(PinholeCamera, RejectsInvalidParameters) {
  EXPECT_THROW(PinholeCamera(640, 480, 0.0, 500, 320, 240), std::invalid_argument);
  EXPECT_THROW(PinholeCamera(640, 480, 500, -1.0, 320, 240), std::invalid_argument);
  EXPECT_THROW(PinholeCamera(-640, 480, 500, 500, 320, 240), std::invalid_argument);
  EXPECT_THROW(PinholeCamera(640, 480, NAN, 500, 320, 240), std::invalid_argument);
  EXPECT_THROW(PinholeCamera(640, 480, 500, 500, INFINITY, 240), std::invalid_argument);
  try {
    PinholeCamera(640, 480, 0.0, 500, 320, 240);
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("fx"), std::string::npos) << e.what();
  }
}

TEST(Camera, RejectsInvalidDistortion) {
  EXPECT_THROW(Camera(CameraModel::kRadTan, 640, 480, 500, 500, 320, 240, {0.1, NAN, 0, 0, 0}),
               std::invalid_argument);
  EXPECT_THROW(Camera(CameraModel::kRadTan, 640, 480, 500, 500, 320, 240, {0.1, 0.2}),
               std::invalid_argument);
  EXPECT_THROW(Camera(CameraModel::kFov, 640, 480, 500, 500, 320, 240, {0.0}),
               std::invalid_argument);
  EXPECT_THROW(Camera(CameraModel::kFov, 640, 480, 500, 500, 320, 240, {4.0}),
               std::invalid_argument);
  EXPECT_THROW(Camera(CameraModel::kPinhole, 640, 480, 0.0, 500, 320, 240), std::invalid_argument);
}

TEST(Camera, ModelNames) {
  for (const auto model : {CameraModel::kPinhole, CameraModel::kRadTan, CameraModel::kEquidistant,
                           CameraModel::kFov}) {
    EXPECT_EQ(CameraModelFromString(ToString(model)), model);
  }
  EXPECT_EQ(CameraModelFromString("atan"), CameraModel::kFov);
  EXPECT_THROW(CameraModelFromString("kannala"), std::invalid_argument);
}

TEST(Camera, RadTanMatchesOpenCvFormula) {
  // Hand-evaluated distortion of one point with the fr1 coefficients.
  const Camera camera = Fr1RadTan();
  const double x = 0.3, y = -0.2, r2 = x * x + y * y;
  const double radial = 1 + 0.262383 * r2 - 0.953104 * r2 * r2 + 1.163314 * r2 * r2 * r2;
  const double xd = x * radial + 2 * -0.005358 * x * y + 0.002628 * (r2 + 2 * x * x);
  const double yd = y * radial + -0.005358 * (r2 + 2 * y * y) + 2 * 0.002628 * x * y;
  EXPECT_TRUE(camera.Distort({x, y}).isApprox(Eigen::Vector2d(xd, yd), 1e-14));
}

}  // namespace
}  // namespace parallax
