// Inverse-depth filter on rendered sequences with ground-truth depth: convergence from a
// random start, updates of a correct prior, propagation, occluders, scale normalisation.

#include "depth/depth_filter.hpp"

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cstdint>
#include <cstring>

#include "tests/tracking/render_fixture.hpp"

namespace parallax {
namespace {

using test::RenderedKeyframe;

struct ErrorSummary {
  double estimated_fraction = 0.0;  ///< confirmed estimates / eligible pixels with truth
  double median_relative = 0.0;
  double over_10_percent = 0.0;  ///< among confirmed estimates
};

ErrorSummary Summarize(const InverseDepthMap& map, const ImageF& truth) {
  std::vector<double> relative;
  int eligible = 0;
  for (std::size_t i = 0; i < map.valid.size(); ++i) {
    const float d = truth.Data()[i];
    if (!map.eligible[i] || !(d > 0.0f)) continue;
    ++eligible;
    if (!map.IsConfirmed(i)) continue;
    relative.push_back(std::abs(map.idepth_smoothed[i] - d) / d);
  }
  ErrorSummary s;
  if (relative.empty()) return s;
  std::sort(relative.begin(), relative.end());
  s.estimated_fraction = static_cast<double>(relative.size()) / static_cast<double>(eligible);
  s.median_relative = relative[relative.size() / 2];
  s.over_10_percent = static_cast<double>(relative.end() -
                                          std::upper_bound(relative.begin(), relative.end(), 0.1)) /
                      static_cast<double>(relative.size());
  return s;
}

// Variance image of a prior whose standard deviation is `fraction` of each inverse depth.
ImageF RelativeVariance(const ImageF& idepth, float fraction) {
  ImageF variance(idepth.Width(), idepth.Height(), 0.0f);
  for (std::size_t i = 0; i < variance.NumPixels(); ++i) {
    const float sigma = fraction * idepth.Data()[i];
    variance.Data()[i] = sigma * sigma;
  }
  return variance;
}

class DepthFilterTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    scene_ = std::make_unique<synth::Scene>(synth::MakeScene("room", 3));
    synth::SynthOptions options;
    options.frames = 40;
    T_w_kf_ = synth::FramePose(options, *scene_, 0);
    keyframe_ = std::make_unique<RenderedKeyframe>(test::RenderTestKeyframe(*scene_, T_w_kf_));
    for (int i = 1; i <= 15; ++i) frames_.push_back(test::RenderTestFrame(*scene_, Pose(i), i));
  }
  static void TearDownTestSuite() {
    frames_.clear();
    keyframe_.reset();
    scene_.reset();
  }
  // Lateral motion: 1 cm right and 6 mm down per frame, no rotation.
  static SE3d Pose(int i) {
    return T_w_kf_ * SE3d(SO3d(), Eigen::Vector3d(0.01 * i, 0.006 * i, 0.0));
  }
  static StereoFrame Stereo(int i) {
    return {frames_[static_cast<std::size_t>(i - 1)].get(), Pose(i).Inverse() * T_w_kf_};
  }

  static inline std::unique_ptr<synth::Scene> scene_;
  static inline SE3d T_w_kf_;
  static inline std::unique_ptr<RenderedKeyframe> keyframe_;
  static inline std::vector<std::shared_ptr<const Frame>> frames_;
};

TEST_F(DepthFilterTest, ConvergesFromRandomInitialisationWithExactPoses) {
  DepthFilter filter;
  InverseDepthMap map(keyframe_->frame, filter.Options());
  map.InitializeRandom(static_cast<float>(1.0 / keyframe_->mean_depth));
  for (int i = 1; i <= 15; ++i) filter.Update(&map, Stereo(i));
  const ErrorSummary s = Summarize(map, keyframe_->idepth);
  RecordProperty("estimated_fraction", std::to_string(s.estimated_fraction));
  RecordProperty("median_relative_error", std::to_string(s.median_relative));
  RecordProperty("over_10_percent", std::to_string(s.over_10_percent));
  EXPECT_GE(s.estimated_fraction, 0.5);
  EXPECT_LE(s.median_relative, 0.02);
  EXPECT_LE(s.over_10_percent, 0.05);
}

TEST_F(DepthFilterTest, UpdateOfCorrectPriorReducesVarianceAndStaysWithinSigma) {
  DepthFilter filter;
  InverseDepthMap map(keyframe_->frame, filter.Options());
  map.InitializeFromPrior(keyframe_->idepth, RelativeVariance(keyframe_->idepth, 0.05f));
  const std::vector<float> before = map.idepth, var_before = map.variance;
  const std::vector<std::uint16_t> obs_before = map.observations;
  const std::vector<std::uint8_t> valid_before = map.valid;
  const DepthUpdateStats stats = filter.Update(&map, Stereo(8));
  EXPECT_GT(stats.fused, 10000);
  int moved_too_far = 0, variance_grew = 0, grew_beyond_process_noise = 0, fused = 0;
  for (std::size_t i = 0; i < map.valid.size(); ++i) {
    // Fused this time: had the prior and gained an observation (pixels without a prior may be
    // created by the same update and are not part of this property).
    if (!valid_before[i] || !map.valid[i] || map.observations[i] <= obs_before[i]) continue;
    ++fused;
    moved_too_far += std::abs(map.idepth[i] - before[i]) > std::sqrt(var_before[i]);
    variance_grew += map.variance[i] >= var_before[i];
    grew_beyond_process_noise += map.variance[i] > 1.0101f * var_before[i];
  }
  EXPECT_LE(fused, stats.fused);  // a few fused pixels are then removed as outliers
  EXPECT_GT(fused, 0.99 * stats.fused);
  EXPECT_EQ(moved_too_far, 0);
  // The prior carries 1% process noise (x1.01) before fusion, so a nearly uninformative
  // observation can leave the variance up to 1% larger; every other fusion reduces it.
  EXPECT_LT(variance_grew, fused / 100);
  EXPECT_EQ(grew_beyond_process_noise, 0);
  // And the fused estimates are better than the 5% prior.
  EXPECT_LT(Summarize(map, keyframe_->idepth).median_relative, 0.02);
}

// LSD-SLAM's rule: a pixel whose full-range (creation) search fails twice, ambiguous or
// without a match, is not searched again in this keyframe; the search is the update's most
// expensive part and repeats the same failure on the same texture.
TEST_F(DepthFilterTest, FailedCreationSearchesStopAfterTwo) {
  DepthFilter filter;
  InverseDepthMap map(keyframe_->frame, filter.Options());
  const DepthUpdateStats first = filter.Update(&map, Stereo(8));
  ASSERT_GT(first.ambiguous + first.no_match, 100);
  filter.Update(&map, Stereo(8));
  int given_up = 0, given_up_but_valid = 0;
  for (std::size_t i = 0; i < map.valid.size(); ++i) {
    if (map.blacklist[i] >= -1) continue;
    ++given_up;
    given_up_but_valid += map.valid[i];
  }
  EXPECT_GT(given_up, 50);
  EXPECT_EQ(given_up_but_valid, 0);
  const DepthUpdateStats third = filter.Update(&map, Stereo(8));
  EXPECT_EQ(third.attempted, first.attempted - given_up);
}

// Hole filling: an empty eligible pixel whose 5x5 window has enough validity takes the
// inverse-variance weighted mean of the valid pixels in it (checked against a direct sum).
// The pixel budget: converged estimates (sigma below 2% of the inverse depth) are re-observed
// one update in four, in turn; the map is as accurate as with every estimate every update.
TEST_F(DepthFilterTest, ConvergedEstimatesAreReobservedInTurn) {
  DepthFilterOptions options;
  options.converged_relative_sigma = 0.02f;
  options.converged_recheck = 4;
  DepthFilterOptions every_update;
  every_update.converged_relative_sigma = 0.0f;
  const DepthFilter budget(options), full(every_update);
  InverseDepthMap map(keyframe_->frame, budget.Options());
  map.InitializeFromPrior(keyframe_->idepth, RelativeVariance(keyframe_->idepth, 0.05f));
  InverseDepthMap reference(keyframe_->frame, full.Options());
  reference.InitializeFromPrior(keyframe_->idepth, RelativeVariance(keyframe_->idepth, 0.05f));
  int skipped = 0;
  for (int i = 1; i <= 12; ++i) {
    int converged = 0;
    for (std::size_t k = 0; k < map.valid.size(); ++k) {
      converged += map.valid[k] && map.variance[k] < 4e-4f * map.idepth[k] * map.idepth[k];
    }
    const DepthUpdateStats stats = budget.Update(&map, Stereo(1 + (i % 15)));
    full.Update(&reference, Stereo(1 + (i % 15)));
    // Three in four of the converged estimates wait for their turn.
    EXPECT_NEAR(stats.converged_skipped, 0.75 * converged, 0.03 * converged + 10) << i;
    skipped += stats.converged_skipped;
  }
  EXPECT_GT(skipped, 50000);  // most estimates converge within the first updates
  const double with_budget = Summarize(map, keyframe_->idepth).median_relative;
  const double without = Summarize(reference, keyframe_->idepth).median_relative;
  RecordProperty("median_relative_error_budget", std::to_string(with_budget));
  RecordProperty("median_relative_error_full", std::to_string(without));
  EXPECT_LT(with_budget, 1.2 * without);
}

TEST_F(DepthFilterTest, FillHolesTakesTheWeightedMeanOfTheWindow) {
  DepthFilter filter;
  InverseDepthMap map(keyframe_->frame, filter.Options());
  std::vector<std::size_t> eligible;
  for (std::size_t i = 0; i < map.eligible.size(); ++i)
    if (map.eligible[i]) eligible.push_back(i);
  ASSERT_GT(eligible.size(), 10000u);
  // Every third eligible pixel valid, with varied depth and variance.
  for (std::size_t k = 0; k < eligible.size(); k += 3) {
    const std::size_t i = eligible[k];
    map.valid[i] = 1;
    map.idepth[i] = 0.5f + 0.001f * static_cast<float>(k % 997);
    map.variance[i] = 1e-4f * (1.0f + static_cast<float>(k % 7));
    map.validity[i] = 10.0f + static_cast<float>(k % 5);
  }
  const InverseDepthMap before = map;
  const int filled = filter.FillHoles(&map);
  EXPECT_GT(filled, 1000);
  int checked = 0, wrongly_filled = 0;
  for (int y = 2; y < map.Height() - 2; ++y) {
    for (int x = 2; x < map.Width() - 2; ++x) {
      const std::size_t i = map.Index(x, y);
      if (before.valid[i] || !before.eligible[i]) continue;
      double support = 0.0, sum_w = 0.0, sum_wd = 0.0;
      for (int dy = -2; dy <= 2; ++dy) {
        for (int dx = -2; dx <= 2; ++dx) {
          const std::size_t j = map.Index(x + dx, y + dy);
          if (!before.valid[j]) continue;
          support += before.validity[j];
          sum_w += 1.0 / before.variance[j];
          sum_wd += before.idepth[j] / before.variance[j];
        }
      }
      if (support <= filter.Options().fill_validity) {
        wrongly_filled += map.valid[i];
        continue;
      }
      ASSERT_TRUE(map.valid[i]) << x << "," << y;
      EXPECT_NEAR(map.idepth[i], sum_wd / sum_w, 1e-5);
      ++checked;
    }
  }
  EXPECT_EQ(checked, filled);
  EXPECT_EQ(wrongly_filled, 0);
}

TEST_F(DepthFilterTest, PropagationKeepsVisiblePoints) {
  DepthFilter filter;
  InverseDepthMap map(keyframe_->frame, filter.Options());
  map.InitializeFromPrior(keyframe_->idepth, RelativeVariance(keyframe_->idepth, 0.02f));
  const RenderedKeyframe next = test::RenderTestKeyframe(*scene_, Pose(12));
  const SE3d T_new_old = Pose(12).Inverse() * T_w_kf_;
  PropagationStats stats;
  const InverseDepthMap propagated =
      filter.Propagate(map, next.frame, T_new_old, 1.0f, 0.0f, &stats);
  // Points that stay visible: they project inside the new image onto the same surface
  // (ground-truth depth agrees within 2%) and land on a pixel the new map could hold.
  const PinholeCamera& K = next.frame->Camera(0);
  int visible = 0, kept = 0;
  for (int y = 0; y < map.Height(); ++y) {
    for (int x = 0; x < map.Width(); ++x) {
      const std::size_t i = map.Index(x, y);
      if (!map.valid[i]) continue;
      const Eigen::Vector3d p = T_new_old * (K.Unproject(Eigen::Vector2d(x, y)) / map.idepth[i]);
      const Eigen::Vector2d uv = K.Project(p);
      const int nx = static_cast<int>(std::lround(uv.x())),
                ny = static_cast<int>(std::lround(uv.y()));
      if (p.z() <= 0 || nx < 3 || ny < 3 || nx >= K.Width() - 3 || ny >= K.Height() - 3) continue;
      const float truth = next.idepth(nx, ny);
      if (!(truth > 0.0f) || std::abs(1.0 / p.z() - truth) > 0.02 * truth ||
          !propagated.eligible[propagated.Index(nx, ny)])
        continue;
      ++visible;
      kept += propagated.valid[propagated.Index(nx, ny)] != 0;
    }
  }
  ASSERT_GT(visible, 10000);
  RecordProperty("kept_of_visible", std::to_string(static_cast<double>(kept) / visible));
  EXPECT_GE(static_cast<double>(kept) / visible, 0.8) << "kept " << kept << " of " << visible;
  // Error not worse than the 2% prior (exact pose): median within 1%.
  const ErrorSummary s = Summarize(propagated, next.idepth);
  EXPECT_LT(s.median_relative, 0.01);
  EXPECT_LT(s.over_10_percent, 0.02);
}

// Every per-pixel array, bit for bit.
bool SameMap(const InverseDepthMap& a, const InverseDepthMap& b) {
  const auto same = [](const auto& u, const auto& v) {
    return u.size() == v.size() && std::memcmp(u.data(), v.data(), u.size() * sizeof(u[0])) == 0;
  };
  return same(a.idepth, b.idepth) && same(a.variance, b.variance) &&
         same(a.idepth_smoothed, b.idepth_smoothed) &&
         same(a.variance_smoothed, b.variance_smoothed) && same(a.validity, b.validity) &&
         same(a.blacklist, b.blacklist) && same(a.valid, b.valid) &&
         same(a.observations, b.observations) && a.updates == b.updates;
}

TEST_F(DepthFilterTest, UpdatesAndPropagationAreTheSameForAnyThreadCount) {
  // Rows run in parallel and a map reuses its working memory from one update to the next:
  // neither may change a bit. Five updates from a random start (creations, fusions,
  // removals), then a propagation (collisions resolved in pixel order) and hole filling.
  const auto run = [&](int threads) {
    tbb::task_arena arena(threads);
    std::unique_ptr<InverseDepthMap> propagated;
    arena.execute([&] {
      const DepthFilter filter;
      InverseDepthMap map(keyframe_->frame, filter.Options());
      map.InitializeRandom(1.0f);
      for (int i = 1; i <= 5; ++i) filter.Update(&map, Stereo(i));
      const InverseDepthMap copy = map;  // a copy starts without working memory
      EXPECT_TRUE(SameMap(copy, map));
      propagated = std::make_unique<InverseDepthMap>(
          filter.Propagate(map, frames_[9], Pose(10).Inverse() * T_w_kf_));
    });
    return propagated;
  };
  const auto one = run(1), two = run(2);
  EXPECT_GT(one->NumValid(), 10000u);
  EXPECT_TRUE(SameMap(*one, *two));
}

TEST_F(DepthFilterTest, APropagatedMapOnRecycledArraysIsTheSameAndReusesTheirMemory) {
  // The mapper hands the arrays of the map it last dropped to the next propagated one. They
  // hold that map's values, made odd here everywhere: each must be overwritten.
  const DepthFilter filter;
  InverseDepthMap map(keyframe_->frame, filter.Options());
  map.InitializeRandom(1.0f);
  for (int i = 1; i <= 5; ++i) filter.Update(&map, Stereo(i));
  InverseDepthMap dropped = map;
  for (std::vector<float>* v : {&dropped.idepth, &dropped.variance, &dropped.idepth_smoothed,
                                &dropped.variance_smoothed, &dropped.validity}) {
    std::fill(v->begin(), v->end(), 3.5f);
  }
  std::fill(dropped.blacklist.begin(), dropped.blacklist.end(), std::int16_t{-7});
  std::fill(dropped.valid.begin(), dropped.valid.end(), std::uint8_t{1});
  std::fill(dropped.eligible.begin(), dropped.eligible.end(), std::uint8_t{1});
  std::fill(dropped.observations.begin(), dropped.observations.end(), std::uint16_t{99});
  const float* memory = dropped.variance_smoothed.data();
  MapScratch scratch;
  scratch.recycled = dropped.TakeArrays();
  EXPECT_TRUE(dropped.idepth.empty());

  const SE3d T_new_old = Pose(10).Inverse() * T_w_kf_;
  const InverseDepthMap fresh = filter.Propagate(map, frames_[9], T_new_old);
  const InverseDepthMap recycled =
      filter.Propagate(map, frames_[9], T_new_old, 1.0f, 0.0f, nullptr, std::move(scratch));
  EXPECT_GT(fresh.NumValid(), 10000u);
  EXPECT_TRUE(SameMap(fresh, recycled));
  EXPECT_EQ(fresh.eligible, recycled.eligible);
  EXPECT_EQ(recycled.variance_smoothed.data(), memory);
}

TEST_F(DepthFilterTest, PropagationTransportsVarianceWithDepthChange) {
  // Moving 0.4 m forward makes points nearer: idepth grows by d_new/d_old and the variance
  // by (d_new/d_old)^4 (first-order transport of 1/z).
  DepthFilter filter;
  InverseDepthMap map(keyframe_->frame, filter.Options());
  map.InitializeFromPrior(keyframe_->idepth, RelativeVariance(keyframe_->idepth, 0.02f));
  const SE3d T_w_new = T_w_kf_ * SE3d(SO3d(), Eigen::Vector3d(0.0, 0.0, 0.4));
  const RenderedKeyframe next = test::RenderTestKeyframe(*scene_, T_w_new);
  const SE3d T_new_old = T_w_new.Inverse() * T_w_kf_;
  const InverseDepthMap propagated = filter.Propagate(map, next.frame, T_new_old);
  const PinholeCamera& K = next.frame->Camera(0);
  int checked = 0, matching = 0;
  for (int y = 0; y < map.Height(); y += 3) {
    for (int x = 0; x < map.Width(); x += 3) {
      const std::size_t i = map.Index(x, y);
      if (!map.valid[i]) continue;
      const Eigen::Vector3d p = T_new_old * (K.Unproject(Eigen::Vector2d(x, y)) / map.idepth[i]);
      const Eigen::Vector2d uv = K.Project(p);
      const int nx = static_cast<int>(std::lround(uv.x())),
                ny = static_cast<int>(std::lround(uv.y()));
      if (!K.IsInside(uv, 4.0)) continue;
      const std::size_t j = propagated.Index(nx, ny);
      if (!propagated.valid[j]) continue;
      const double ratio = (1.0 / p.z()) / map.idepth[i];
      ++checked;
      matching +=
          std::abs(propagated.variance[j] / (std::pow(ratio, 4) * map.variance[i]) - 1.0) < 0.15;
    }
  }
  ASSERT_GT(checked, 1000);
  // Collisions merge several sources into one pixel (smaller variance); most are single.
  EXPECT_GT(static_cast<double>(matching) / checked, 0.5) << matching << " of " << checked;
}

TEST_F(DepthFilterTest, OccluderDoesNotCorruptBackground) {
  // The same room with a box 0.8 m in front of the camera in every frame after the keyframe.
  synth::Scene occluded = synth::MakeScene("room", 3);
  const Eigen::Vector3d centre = T_w_kf_ * Eigen::Vector3d(0.15, 0.0, 0.8);
  synth::AddBox(&occluded, centre - Eigen::Vector3d(0.15, 0.15, 0.05),
                centre + Eigen::Vector3d(0.15, 0.15, 0.05), 4, 0.3);
  DepthFilter filter;
  InverseDepthMap map(keyframe_->frame, filter.Options());
  map.InitializeFromPrior(keyframe_->idepth, RelativeVariance(keyframe_->idepth, 0.05f));
  std::vector<std::uint8_t> hidden(map.valid.size(), 0);
  for (int i = 1; i <= 10; ++i) {
    const auto frame = test::RenderTestFrame(occluded, Pose(i), 100 + i);
    const synth::RenderedView view = synth::Render(occluded, test::TestCamera(), Pose(i));
    // Mark keyframe pixels whose background point is hidden by the box in this frame.
    const SE3d T_f_kf = Pose(i).Inverse() * T_w_kf_;
    const PinholeCamera K = test::TestCamera();
    for (int y = 0; y < map.Height(); ++y) {
      for (int x = 0; x < map.Width(); ++x) {
        const std::size_t k = map.Index(x, y);
        if (!(keyframe_->idepth.Data()[k] > 0.0f)) continue;
        const Eigen::Vector3d p =
            T_f_kf * (K.Unproject(Eigen::Vector2d(x, y)) / keyframe_->idepth.Data()[k]);
        const Eigen::Vector2d uv = K.Project(p);
        if (!K.IsInside(uv)) continue;
        const float z = view.depth(static_cast<int>(std::lround(uv.x())),
                                   static_cast<int>(std::lround(uv.y())));
        hidden[k] |= z > 0.0f && z < 0.9 * p.z();
      }
    }
    filter.Update(&map, {frame.get(), T_f_kf});
  }
  int hidden_valid = 0, corrupted = 0, hidden_total = 0;
  for (std::size_t k = 0; k < hidden.size(); ++k) {
    if (!hidden[k] || !map.eligible[k]) continue;
    ++hidden_total;
    if (!map.valid[k]) continue;
    ++hidden_valid;
    const float d = keyframe_->idepth.Data()[k];
    corrupted += std::abs(map.idepth_smoothed[k] - d) > 0.1f * d;
  }
  ASSERT_GT(hidden_total, 2000);
  RecordProperty("hidden_pixels", hidden_total);
  RecordProperty("hidden_still_valid", hidden_valid);
  RecordProperty("hidden_corrupted", corrupted);
  EXPECT_LE(corrupted, hidden_total / 50)
      << corrupted << " of " << hidden_total << " background pixels corrupted";
}

TEST_F(DepthFilterTest, ScaleNormalisationMakesMeanInverseDepthOne) {
  DepthFilter filter;
  InverseDepthMap map(keyframe_->frame, filter.Options());
  ImageF prior_var(map.Width(), map.Height(), 1e-4f);
  map.InitializeFromPrior(keyframe_->idepth, prior_var);
  const double mean = map.MeanSmoothedIdepth();
  const float s = filter.NormalizeScale(&map);
  EXPECT_NEAR(s, 1.0 / mean, 1e-6);
  EXPECT_NEAR(map.MeanSmoothedIdepth(), 1.0, 1e-5);
  InverseDepthMap empty(keyframe_->frame, filter.Options());
  EXPECT_EQ(filter.NormalizeScale(&empty), 1.0f);
}

TEST(DepthFilterOptions, RejectBadValues) {
  DepthFilterOptions options;
  options.max_idepth = 0.0f;
  EXPECT_THROW(options.Check(), std::invalid_argument);
  options = {};
  options.initial_variance = 1.0f;  // above max_variance
  EXPECT_THROW(DepthFilter{options}, std::invalid_argument);
}

}  // namespace
}  // namespace parallax
