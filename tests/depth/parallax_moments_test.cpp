// ParallaxMoments: the keyframe rule's image distance against the points' projected motion.
#include "depth/parallax_moments.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "depth/depth_filter.hpp"
#include "tests/tracking/render_fixture.hpp"

namespace parallax {
namespace {

class ParallaxMomentsTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    scene_ = std::make_unique<synth::Scene>(synth::MakeScene("room", 3));
    synth::SynthOptions options;
    const SE3d T_w_kf = synth::FramePose(options, *scene_, 0);
    keyframe_ = std::make_unique<test::RenderedKeyframe>(test::RenderTestKeyframe(*scene_, T_w_kf));
    map_ = std::make_unique<InverseDepthMap>(keyframe_->frame, DepthFilterOptions{});
    map_->InitializeFromPrior(keyframe_->idepth, keyframe_->variance);
  }
  static void TearDownTestSuite() {
    map_.reset();
    keyframe_.reset();
    scene_.reset();
  }

  // The distance measured point by point: every valid pixel's point moved by -t (the frame
  // at t sees it there) and projected exactly; sqrt(E[|flow|^2] / E[rho^2]) * E[rho] in
  // normalised coordinates.
  static double ProjectedDistance(const Eigen::Vector3d& t_kf_frame) {
    const PinholeCamera& camera = map_->Keyframe().Camera(0);
    double flow2 = 0.0, rho = 0.0, rho2 = 0.0, n = 0.0;
    for (int v = 0; v < map_->Height(); ++v) {
      for (int u = 0; u < map_->Width(); ++u) {
        const std::size_t i = map_->Index(u, v);
        if (!map_->valid[i]) continue;
        const double r = map_->idepth_smoothed[i];
        const Eigen::Vector3d ray = camera.Unproject(Eigen::Vector2d(u, v));
        const Eigen::Vector3d moved = ray / r - t_kf_frame;
        const Eigen::Vector2d flow = moved.head<2>() / moved.z() - ray.head<2>();
        flow2 += flow.squaredNorm();
        rho += r;
        rho2 += r * r;
        n += 1.0;
      }
    }
    return std::sqrt(flow2 / rho2) * rho / n;
  }

  static inline std::unique_ptr<synth::Scene> scene_;
  static inline std::unique_ptr<test::RenderedKeyframe> keyframe_;
  static inline std::unique_ptr<InverseDepthMap> map_;
};

TEST_F(ParallaxMomentsTest, MeanInverseDepthIsTheMapsOwnToTheBit) {
  ASSERT_GT(map_->NumValid(), 10000u);
  // The rule with keyframe_distance_in_image off must decide exactly as before.
  EXPECT_EQ(ComputeParallaxMoments(*map_).mean_idepth, map_->MeanSmoothedIdepth());
}

TEST_F(ParallaxMomentsTest, ASidewaysStepIsItsLengthTimesTheMeanInverseDepth) {
  const ParallaxMoments m = ComputeParallaxMoments(*map_);
  const Eigen::Vector3d t(0.03, -0.04, 0.0);
  EXPECT_NEAR(m.ImageDistance(t), 0.05 * m.mean_idepth, 1e-12);
  // ... which the points' projected motion confirms (first order: a 1% step is close).
  EXPECT_NEAR(m.ImageDistance(0.2 * t), ProjectedDistance(0.2 * t),
              0.02 * m.ImageDistance(0.2 * t));
}

TEST_F(ParallaxMomentsTest, AStepAlongTheViewCountsByHowFarItMovesThePoints) {
  const ParallaxMoments m = ComputeParallaxMoments(*map_);
  for (const Eigen::Vector3d& t :
       {Eigen::Vector3d(0.0, 0.0, 0.01), Eigen::Vector3d(0.0, 0.0, -0.01),
        Eigen::Vector3d(0.004, 0.002, 0.01)}) {
    const double expected = ProjectedDistance(t);
    EXPECT_NEAR(m.ImageDistance(t), expected, 0.03 * expected) << t.transpose();
    // Forward motion moves the points less than the same step sideways.
    EXPECT_LT(m.ImageDistance(t), 0.8 * t.norm() * m.mean_idepth) << t.transpose();
  }
}

TEST_F(ParallaxMomentsTest, AnEmptyMapHasNoDistance) {
  const InverseDepthMap empty(keyframe_->frame, DepthFilterOptions{});
  const ParallaxMoments m = ComputeParallaxMoments(empty);
  EXPECT_EQ(m.mean_idepth, 0.0);
  EXPECT_EQ(m.ImageDistance(Eigen::Vector3d(1.0, 2.0, 3.0)), 0.0);
}

}  // namespace
}  // namespace parallax
