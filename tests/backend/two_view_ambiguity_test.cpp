// Homography share and twin motions of two-view correspondences with known geometry.

#include "backend/two_view_ambiguity.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "core/se3.hpp"

namespace parallax {
namespace {

constexpr double kDegPerRad = 180.0 / std::numbers::pi;

PinholeCamera TestCamera() { return {640, 480, 525.0, 525.0, 319.5, 239.5}; }

/// Points seen by the reference camera at pixels on a grid, at depth `depth(u, v)`, projected
/// into a camera moved by T_ref_cur; pixel noise of `sigma` (fixed seed).
template <typename Depth>
PixelCorrespondences Project(const SE3d& T_ref_cur, Depth depth, double sigma) {
  std::mt19937 rng(5);
  std::normal_distribution<double> noise(0.0, sigma);
  const PinholeCamera camera = TestCamera();
  PixelCorrespondences c;
  const SE3d T_cur_ref = T_ref_cur.Inverse();
  for (double v = 40.0; v < 440.0; v += 20.0) {
    for (double u = 40.0; u < 600.0; u += 20.0) {
      const double z = depth(u, v);
      const Eigen::Vector3d p_ref((u - camera.Cx()) / camera.Fx() * z,
                                  (v - camera.Cy()) / camera.Fy() * z, z);
      const Eigen::Vector3d p_cur = T_cur_ref * p_ref;
      if (p_cur.z() <= 0.1) continue;
      const Eigen::Vector2d x = camera.Project(p_cur);
      c.ref.emplace_back(u + noise(rng), v + noise(rng));
      c.cur.emplace_back(x.x() + noise(rng), x.y() + noise(rng));
    }
  }
  return c;
}

RelativePose TruePose(const SE3d& T_ref_cur) {
  const SE3d T_cur_ref = T_ref_cur.Inverse();
  return {T_cur_ref.Rotation(), T_cur_ref.Translation().normalized()};
}

// Mostly forward with a little sideways and a pitch, as on the TUM clip's start.
SE3d ForwardStep() {
  return {SO3d::Exp(Eigen::Vector3d(-3.0 / kDegPerRad, -1.5 / kDegPerRad, 0.0)),
          Eigen::Vector3d(-0.01, 0.03, 0.15)};
}

TEST(TwoViewAmbiguity, APlaneIsAHomographyAndHasATwinThatExplainsItAsWell) {
  // A tilted plane (depth 1.5 m at the top of the image, 2.5 m at the bottom).
  const auto plane = [](double, double v) { return 1.0 / (1.0 / 1.5 - v / 480.0 * 0.27); };
  const PixelCorrespondences c = Project(ForwardStep(), plane, 0.2);
  const auto H = FitHomography(c, 1.0);
  ASSERT_TRUE(H.has_value());
  EXPECT_GT(HomographyShare(*H, c, 1.0), 0.97);
  const std::optional<double> ratio = TwinCostRatio(TestCamera(), *H, c, TruePose(ForwardStep()));
  ASSERT_TRUE(ratio.has_value());
  EXPECT_LT(*ratio, 1.1);  // noise decides between the two motions (measured 0.94)
}

TEST(TwoViewAmbiguity, ReliefLeavesNoTwinThatExplainsTheMatches) {
  // A plane with boxes in front: a third of the points at 0.8 m instead of 2 m.
  const auto relief = [](double u, double v) {
    return (static_cast<int>(u / 100.0) + static_cast<int>(v / 100.0)) % 3 == 0 ? 0.8 : 2.0;
  };
  const PixelCorrespondences c = Project(ForwardStep(), relief, 0.3);
  const auto H = FitHomography(c, 1.0);
  ASSERT_TRUE(H.has_value());
  EXPECT_LT(HomographyShare(*H, c, 1.0), 0.8);
  const std::optional<double> ratio = TwinCostRatio(TestCamera(), *H, c, TruePose(ForwardStep()));
  // Both motions of the homography (fitted to the far plane) polish to the true one on all
  // points (measured: no twin left); a twin, if any, must explain them far worse.
  EXPECT_TRUE(!ratio.has_value() || *ratio > 2.0);
}

TEST(TwoViewAmbiguity, TheSameMotionIsNotATwin) {
  // Polishing the pose itself converges to it: the plane's other motion is the only twin, and
  // its rotation differs from the true one.
  const auto plane = [](double, double) { return 2.0; };
  const PixelCorrespondences c = Project(ForwardStep(), plane, 0.3);
  const auto H = FitHomography(c, 1.0);
  ASSERT_TRUE(H.has_value());
  const RelativePose truth = TruePose(ForwardStep());
  // With thresholds so large that every motion counts as the same, there is no twin.
  EXPECT_FALSE(TwinCostRatio(TestCamera(), *H, c, truth, 180.0, 90.0).has_value());
  EXPECT_TRUE(TwinCostRatio(TestCamera(), *H, c, truth).has_value());
}

TEST(TwoViewAmbiguity, TooFewCorrespondencesFitNoHomography) {
  PixelCorrespondences c;
  c.ref = {{1.0, 2.0}, {3.0, 4.0}, {5.0, 1.0}};
  c.cur = c.ref;
  EXPECT_FALSE(FitHomography(c, 1.0).has_value());
}

}  // namespace
}  // namespace parallax
