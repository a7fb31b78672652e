// Calibration plausibility: real calibrations pass, typos and impossible lenses are named.

#include "core/calibration_check.hpp"

#include <gtest/gtest.h>

namespace parallax {
namespace {

Camera RadTan(double fx, double cx, std::vector<double> d) {
  return Camera(CameraModel::kRadTan, 640, 480, fx, fx, cx, 240.0, std::move(d));
}

TEST(CalibrationCheck, RealCalibrationsPass) {
  // TUM freiburg1, EuRoC cam0, KITTI 07, a TUM monoVO-like fisheye and an FOV lens.
  EXPECT_EQ(
      CalibrationProblem(Camera(CameraModel::kRadTan, 640, 480, 517.306408, 516.469215, 318.643040,
                                255.313989, {0.262383, -0.953104, -0.005358, 0.002628, 1.163314})),
      "");
  EXPECT_EQ(
      CalibrationProblem(Camera(CameraModel::kRadTan, 752, 480, 458.654, 457.296, 367.215, 248.375,
                                {-0.28340811, 0.07395907, 0.00019359, 1.76187114e-05, 0.0})),
      "");
  EXPECT_EQ(CalibrationProblem(Camera(CameraModel::kPinhole, 1226, 370, 707.0912, 707.0912,
                                      601.8873, 183.1104, {})),
            "");
  EXPECT_EQ(CalibrationProblem(Camera(CameraModel::kEquidistant, 1280, 1024, 380.8, 380.8, 640.0,
                                      512.0, {0.010, -0.004, 0.002, -0.0005})),
            "");
  EXPECT_EQ(
      CalibrationProblem(Camera(CameraModel::kFov, 640, 480, 277.0, 291.0, 312.0, 239.0, {0.9})),
      "");
  EXPECT_EQ(CalibrationProblem(RadTan(500.0, 320.0, {0, 0, 0, 0, 0})), "");  // all-zero distortion
}

void ExpectProblem(const Camera& camera, const std::string& fragment) {
  const std::string problem = CalibrationProblem(camera);
  EXPECT_NE(problem.find(fragment), std::string::npos) << "got: '" << problem << "'";
}

TEST(CalibrationCheck, ImplausibleCalibrationsAreNamed) {
  ExpectProblem(RadTan(1e100, 320.0, {0, 0, 0, 0, 0}), "fx = 1e+100");
  ExpectProblem(RadTan(1e-9, 320.0, {0, 0, 0, 0, 0}), "fx = 1e-09");
  ExpectProblem(Camera(CameraModel::kPinhole, 640, 480, 500.0, 100.0, 320.0, 240.0, {}), "aspect");
  ExpectProblem(RadTan(500.0, 5000.0, {0, 0, 0, 0, 0}), "principal point");
  ExpectProblem(RadTan(500.0, 320.0, {1e6, 0, 0, 0, 0}), "radius");  // k1 = 1e6
  // Strong barrel distortion that folds before the border: r (1 - 2 r^2) peaks at r = 0.41.
  ExpectProblem(RadTan(300.0, 320.0, {-2.0, 0, 0, 0, 0}), "distortion");
  ExpectProblem(Camera(CameraModel::kEquidistant, 640, 480, 200.0, 200.0, 320.0, 240.0,
                       {-5.0, 0.0, 0.0, 0.0}),
                "distortion");
}

}  // namespace
}  // namespace parallax
