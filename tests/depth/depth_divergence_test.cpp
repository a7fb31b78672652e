// Numerical divergence in the depth filter (docs/reliability.md, "Divergence"): estimates
// that went non-finite or non-positive are removed where a stage hands its map on, counted,
// and never reach the smoothed map, a propagated keyframe or the scale normalisation.

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "core/divergence.hpp"
#include "depth/depth_filter.hpp"
#include "tests/tracking/render_fixture.hpp"

namespace parallax {
namespace {

using test::RenderedKeyframe;

constexpr float kNan = std::numeric_limits<float>::quiet_NaN();
constexpr float kInf = std::numeric_limits<float>::infinity();

class DepthDivergenceTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    scene_ = std::make_unique<synth::Scene>(synth::MakeScene("room", 5));
    synth::SynthOptions options;
    options.frames = 40;
    T_w_kf_ = synth::FramePose(options, *scene_, 0);
    keyframe_ = std::make_unique<RenderedKeyframe>(test::RenderTestKeyframe(*scene_, T_w_kf_));
    T_w_frame_ = T_w_kf_ * SE3d(SO3d(), Eigen::Vector3d(0.06, 0.03, 0.0));
    frame_ = test::RenderTestFrame(*scene_, T_w_frame_, 1);
  }
  static void TearDownTestSuite() {
    frame_.reset();
    keyframe_.reset();
    scene_.reset();
  }

  // A map initialised from the true depth (5% prior) with four estimates corrupted the ways
  // an estimator diverges; returns their indices.
  static std::vector<std::size_t> CorruptedMap(InverseDepthMap* map) {
    ImageF variance(keyframe_->idepth.Width(), keyframe_->idepth.Height(), 0.0f);
    for (std::size_t i = 0; i < variance.NumPixels(); ++i) {
      const float sigma = 0.05f * keyframe_->idepth.Data()[i];
      variance.Data()[i] = sigma * sigma;
    }
    map->InitializeFromPrior(keyframe_->idepth, variance);
    std::vector<std::size_t> valid;
    for (std::size_t i = 0; i < map->valid.size(); ++i) {
      if (map->valid[i]) valid.push_back(i);
    }
    EXPECT_GT(valid.size(), 1000u);
    std::vector<std::size_t> bad = {valid[valid.size() / 5], valid[2 * valid.size() / 5],
                                    valid[3 * valid.size() / 5], valid[4 * valid.size() / 5]};
    map->idepth[bad[0]] = kNan;
    map->variance[bad[1]] = kInf;
    map->idepth[bad[2]] = -map->idepth[bad[2]];
    map->variance[bad[3]] = 0.0f;
    return bad;
  }

  static std::vector<std::size_t> UnhealthyValid(const InverseDepthMap& map) {
    std::vector<std::size_t> unhealthy;
    for (std::size_t i = 0; i < map.valid.size(); ++i) {
      if (map.valid[i] && (!HealthyEstimate(map.idepth[i], map.variance[i]) ||
                           !HealthyEstimate(map.idepth_smoothed[i], map.variance_smoothed[i]))) {
        unhealthy.push_back(i);
      }
    }
    return unhealthy;
  }

  static inline std::unique_ptr<synth::Scene> scene_;
  static inline SE3d T_w_kf_, T_w_frame_;
  static inline std::unique_ptr<RenderedKeyframe> keyframe_;
  static inline std::shared_ptr<const Frame> frame_;
};

TEST_F(DepthDivergenceTest, AnUpdateRemovesDivergedEstimatesAndCountsThem) {
  const DepthFilter filter;
  InverseDepthMap clean(keyframe_->frame, filter.Options());
  InverseDepthMap map(keyframe_->frame, filter.Options());
  const std::vector<std::size_t> bad = CorruptedMap(&map);
  CorruptedMap(&clean);
  for (const std::size_t i : bad) {  // the same map without the corruption
    clean.idepth[i] = keyframe_->idepth.Data()[i];
    clean.variance[i] = 0.0025f * clean.idepth[i] * clean.idepth[i];
  }
  const StereoFrame stereo{frame_.get(), T_w_frame_.Inverse() * T_w_kf_};
  const DepthUpdateStats clean_stats = filter.Update(&clean, stereo);
  const DepthUpdateStats stats = filter.Update(&map, stereo);
  EXPECT_EQ(clean_stats.diverged, 0);
  EXPECT_EQ(stats.diverged, 4);
  for (const std::size_t i : bad) EXPECT_FALSE(map.valid[i]) << i;
  EXPECT_TRUE(UnhealthyValid(map).empty());
  // The rest of the map is updated as if nothing had happened (the four pixels and their
  // 5x5 neighbourhoods may differ).
  EXPECT_NEAR(stats.fused, clean_stats.fused, 4 * 25);
}

TEST_F(DepthDivergenceTest, RegularisationRemovesWhatAStageLeftDiverged) {
  const DepthFilter filter;
  InverseDepthMap map(keyframe_->frame, filter.Options());
  CorruptedMap(&map);
  EXPECT_EQ(filter.Regularize(&map), 4);
  EXPECT_TRUE(UnhealthyValid(map).empty());
  EXPECT_EQ(filter.Regularize(&map), 0);
}

TEST_F(DepthDivergenceTest, PropagationLeavesDivergedEstimatesBehind) {
  const DepthFilter filter;
  InverseDepthMap map(keyframe_->frame, filter.Options());
  CorruptedMap(&map);
  PropagationStats stats;
  const InverseDepthMap next =
      filter.Propagate(map, frame_, T_w_frame_.Inverse() * T_w_kf_, 1.0f, 0.0f, &stats);
  EXPECT_EQ(stats.diverged, 4);
  EXPECT_GT(stats.propagated, 1000);
  EXPECT_TRUE(UnhealthyValid(next).empty());
}

TEST_F(DepthDivergenceTest, ScaleNormalisationRefusesAMapWhoseMeanIsNotFinite) {
  const DepthFilter filter;
  InverseDepthMap map(keyframe_->frame, filter.Options());
  CorruptedMap(&map);
  filter.Regularize(&map);
  std::size_t first = 0;
  while (!map.valid[first]) ++first;
  map.idepth_smoothed[first] = kInf;
  const std::vector<float> before = map.idepth_smoothed;
  EXPECT_THROW(filter.NormalizeScale(&map), NumericalDivergence);
  EXPECT_EQ(map.idepth_smoothed[first], kInf);  // unchanged: the caller keeps its keyframe
  EXPECT_EQ(map.idepth_smoothed[first + 1], before[first + 1]);
}

TEST(HealthyEstimate, NeedsFinitePositiveDepthAndInvertibleVariance) {
  EXPECT_TRUE(HealthyEstimate(0.5f, 1e-4f));
  EXPECT_FALSE(HealthyEstimate(kNan, 1e-4f));
  EXPECT_FALSE(HealthyEstimate(kInf, 1e-4f));
  EXPECT_FALSE(HealthyEstimate(0.0f, 1e-4f));
  EXPECT_FALSE(HealthyEstimate(-0.5f, 1e-4f));
  EXPECT_FALSE(HealthyEstimate(0.5f, 0.0f));
  EXPECT_FALSE(HealthyEstimate(0.5f, kInf));
  EXPECT_FALSE(HealthyEstimate(0.5f, kNan));
  EXPECT_FALSE(HealthyEstimate(0.5f, 1e-45f));  // denormal: 1 / variance overflows
}

}  // namespace
}  // namespace parallax
