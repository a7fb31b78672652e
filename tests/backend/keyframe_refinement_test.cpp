// Joint refinement of a keyframe's depth and its frames' poses, on rendered frames with known
// depth and motion: a tilted depth and perturbed poses are pulled back to the truth.

#include "backend/keyframe_refinement.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iterator>
#include <string>

#include "tests/tools/temp_dir.hpp"
#include "tools/dataset/trajectory.hpp"
#include "tools/eval/evaluation.hpp"
#include "tools/run_pipeline.hpp"
#include "tools/synth/renderer.hpp"
#include "tools/synth/synthetic_sequence.hpp"

namespace parallax {
namespace {

double Median(std::vector<double> v) {
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
  return v[v.size() / 2];
}

/// Median |log(idepth / truth) - its median|: the depth's shape error, scale removed.
double ShapeError(const std::vector<float>& idepth, const std::vector<float>& truth) {
  std::vector<double> log_ratio;
  for (std::size_t i = 0; i < idepth.size(); ++i)
    log_ratio.push_back(std::log(idepth[i] / truth[i]));
  const double m = Median(log_ratio);
  for (double& l : log_ratio) l = std::abs(l - m);
  return Median(log_ratio);
}

/// Slope of log(idepth / truth) over the normalised image row y: the tilt.
double Tilt(const std::vector<float>& idepth, const std::vector<float>& truth,
            const std::vector<std::int32_t>& pixel, const PinholeCamera& camera) {
  double n = 0, sy = 0, sl = 0, syy = 0, syl = 0;
  for (std::size_t i = 0; i < idepth.size(); ++i) {
    const int row = pixel[i] / camera.Width();
    const double y = (row - camera.Cy()) / camera.Fy();
    const double l = std::log(idepth[i] / truth[i]);
    n += 1;
    sy += y;
    sl += l;
    syy += y * y;
    syl += y * l;
  }
  return (n * syl - sy * sl) / (n * syy - sy * sy);
}

double RotationErrorDeg(const SE3d& a, const SE3d& b) {
  return (a.Rotation().Inverse() * b.Rotation()).Log().norm() * 180.0 / M_PI;
}

/// Angle between the translation directions (the scale is the gauge's).
double DirectionErrorDeg(const SE3d& a, const SE3d& b) {
  const double c = a.Translation().normalized().dot(b.Translation().normalized());
  return std::acos(std::clamp(c, -1.0, 1.0)) * 180.0 / M_PI;
}

/// Pixels next to a depth discontinuity mix two surfaces' grey levels: no single depth
/// explains them in other views, so the truth is not their optimum.
bool NearADepthEdge(const ImageF& depth, int x, int y) {
  for (int dy = -2; dy <= 2; ++dy) {
    for (int dx = -2; dx <= 2; ++dx) {
      if (std::abs(depth(x + dx, y + dy) - depth(x, y)) > 0.02f * depth(x, y)) return true;
    }
  }
  return false;
}

class KeyframeRefinementTest : public ::testing::Test {
 protected:
  void SetUp() override {
    options_.scene = "room";
    options_.motion = "orbit";
    options_.frames = 90;
    scene_ = synth::MakeScene(options_.scene, options_.seed);
    camera_ = synth::SynthCamera(options_);
    const synth::SynthFrame first = synth::RenderSynthFrame(options_, scene_, 0);
    keyframe_ = std::make_unique<Frame>(0, 0.0, camera_, first.image);
    const SE3d T_w_kf = synth::FramePose(options_, scene_, 0);
    const ImageF& max_gradient = keyframe_->MaxGradient();
    for (int y = 8; y < camera_.Height() - 8; y += 2) {
      for (int x = 8; x < camera_.Width() - 8; x += 2) {
        const float z = first.depth(x, y);
        if (!(z > 0.0f) || max_gradient(x, y) < 8.0f || NearADepthEdge(first.depth, x, y)) continue;
        pixel_.push_back(y * camera_.Width() + x);
        truth_.push_back(1.0f / z);
      }
    }
    for (int i = 2; i <= 24; i += 2) {
      const synth::SynthFrame f = synth::RenderSynthFrame(options_, scene_, i);
      frames_.push_back(std::make_unique<Frame>(i, 0.0, camera_, f.image));
      poses_.push_back(T_w_kf.Inverse() * synth::FramePose(options_, scene_, i));
    }
  }

  synth::SynthOptions options_;
  synth::Scene scene_;
  PinholeCamera camera_{640, 480, 525, 525, 319.5, 239.5};
  std::unique_ptr<Frame> keyframe_;
  std::vector<std::unique_ptr<Frame>> frames_;
  std::vector<SE3d> poses_;  // true T_kf_frame
  std::vector<std::int32_t> pixel_;
  std::vector<float> truth_;
};

/// Largest rotation and translation-direction errors of refined poses, degrees.
std::pair<double, double> PoseErrors(const std::vector<SE3d>& poses,
                                     const std::vector<SE3d>& truth) {
  double rotation = 0.0, direction = 0.0;
  for (std::size_t j = 0; j < poses.size(); ++j) {
    rotation = std::max(rotation, RotationErrorDeg(poses[j], truth[j]));
    direction = std::max(direction, DirectionErrorDeg(poses[j], truth[j]));
  }
  return {rotation, direction};
}

TEST_F(KeyframeRefinementTest, ReducesATiltAndThePoseErrorsThatFitIt) {
  // The distortion the depth filter's alternation leaves on sideways motion: inverse depth
  // tilted along the image's vertical axis (+-9%), with poses perturbed by up to 0.6 degrees.
  std::vector<float> tilted;
  for (std::size_t i = 0; i < pixel_.size(); ++i) {
    const int row = pixel_[i] / camera_.Width();
    const double y = (row - camera_.Cy()) / camera_.Fy();
    tilted.push_back(static_cast<float>(truth_[i] * std::exp(0.2 * y)));
  }
  std::vector<RefinementFrame> frames;
  std::vector<SE3d> start;
  for (std::size_t j = 0; j < frames_.size(); ++j) {
    SE3d::Tangent xi;
    xi << 0.004, -0.003, 0.002, 0.003, -0.004, 0.002;
    frames.push_back(
        {frames_[j].get(), SE3d::Exp(xi * static_cast<double>(j + 1) / 6.0) * poses_[j]});
    start.push_back(frames.back().T_kf_frame);
  }
  const KeyframeRefinementResult r =
      RefineKeyframe(*keyframe_, pixel_, tilted, frames, KeyframeRefinementOptions{});
  const double tilt_before = Tilt(tilted, truth_, pixel_, camera_);
  const double tilt_after = Tilt(r.idepth, truth_, pixel_, camera_);
  const auto [rotation_before, direction_before] = PoseErrors(start, poses_);
  const auto [rotation_after, direction_after] = PoseErrors(r.T_kf_frame, poses_);
  // The tilt is weakly observable over a short window (a near-gauge direction: the poses
  // can rotate to fit it), so it is reduced, not removed (docs/math/keyframe_refinement.md).
  EXPECT_LT(r.final_cost, 0.75 * r.initial_cost);
  EXPECT_LT(tilt_after, 0.95 * tilt_before);
  // The poses rotate to fit part of the tilt that remains (measured 0.62 -> 0.72 degrees).
  EXPECT_LT(rotation_after, 1.25 * rotation_before);
  EXPECT_LT(direction_after, 2.0);
  EXPECT_GT(r.points_refined, static_cast<int>(pixel_.size() * 8 / 10));
}

// On this render the photometric optimum lies 0.2-0.3 degrees from the true poses (with
// points at depth edges excluded; docs/math/keyframe_refinement.md): the bound says that,
// and a sign or Jacobian error would move far beyond it.
TEST_F(KeyframeRefinementTest, StaysNearTheTruth) {
  std::vector<RefinementFrame> frames;
  for (std::size_t j = 0; j < frames_.size(); ++j) frames.push_back({frames_[j].get(), poses_[j]});
  const KeyframeRefinementResult r =
      RefineKeyframe(*keyframe_, pixel_, truth_, frames, KeyframeRefinementOptions{});
  const auto [rotation, direction] = PoseErrors(r.T_kf_frame, poses_);
  EXPECT_LT(rotation, 0.5);
  EXPECT_LT(direction, 1.0);
  EXPECT_LT(std::abs(Tilt(r.idepth, truth_, pixel_, camera_)), 0.02);
  EXPECT_LT(ShapeError(r.idepth, truth_), 0.01);
}

/// Share of `points` whose refined inverse depth differs from the input.
double ShareChanged(const std::vector<std::size_t>& points, const std::vector<float>& input,
                    const std::vector<float>& refined) {
  std::size_t changed = 0;
  for (const std::size_t i : points) changed += refined[i] != input[i];
  return static_cast<double>(changed) /
         static_cast<double>(std::max<std::size_t>(points.size(), 1));
}

// Frames that move straight sideways from the keyframe: epipolar lines run along the rows, so
// a point on a horizontal edge (gradient across the rows) cannot be measured and a point on a
// vertical edge can. The information gate must keep the input value of the first kind and let
// the window correct the second.
TEST_F(KeyframeRefinementTest, TheInformationGateKeepsPointsTheWindowCannotMeasure) {
  const SE3d T_w_kf = synth::FramePose(options_, scene_, 0);
  std::vector<std::unique_ptr<Frame>> sideways;
  std::vector<RefinementFrame> frames;
  for (int k = 1; k <= 6; ++k) {
    const SE3d T_kf_frame(SO3d(), Eigen::Vector3d(0.02 * k, 0.0, 0.0));
    const synth::RenderedView view = synth::Render(scene_, camera_, T_w_kf * T_kf_frame);
    ImageU8 image(camera_.Width(), camera_.Height());
    for (int y = 0; y < image.Height(); ++y) {
      for (int x = 0; x < image.Width(); ++x) {
        image(x, y) =
            static_cast<std::uint8_t>(std::clamp(std::lround(view.intensity(x, y)), 0L, 255L));
      }
    }
    sideways.push_back(std::make_unique<Frame>(k, 0.0, camera_, image));
    frames.push_back({sideways.back().get(), T_kf_frame});
  }
  std::vector<float> noisy;
  std::uint32_t state = 12345u;
  for (const float d : truth_) {
    state = state * 1664525u + 1013904223u;  // fixed pseudo-random, +-3%
    const double u = static_cast<double>(state >> 8) / static_cast<double>(1u << 24) - 0.5;
    noisy.push_back(static_cast<float>(d * std::exp(0.06 * u)));
  }
  const PyramidLevel& level0 = keyframe_->Level(0);
  std::vector<std::size_t> along, across;  // gradient along the epipolar lines / across them
  for (std::size_t i = 0; i < pixel_.size(); ++i) {
    const int x = pixel_[i] % camera_.Width(), y = pixel_[i] / camera_.Width();
    const float gx = std::abs(level0.dx(x, y)), gy = std::abs(level0.dy(x, y));
    if (gx < 0.1f * gy) across.push_back(i);
    if (gy < 0.1f * gx) along.push_back(i);
  }
  ASSERT_GT(across.size(), 100u);
  ASSERT_GT(along.size(), 100u);
  KeyframeRefinementOptions options;
  const KeyframeRefinementResult ungated =
      RefineKeyframe(*keyframe_, pixel_, noisy, frames, options);
  options.max_point_relative_sigma = 0.01f;
  const KeyframeRefinementResult gated = RefineKeyframe(*keyframe_, pixel_, noisy, frames, options);
  const auto subset = [](const std::vector<float>& v, const std::vector<std::size_t>& points) {
    std::vector<float> out;
    out.reserve(points.size());
    for (const std::size_t i : points) out.push_back(v[i]);
    return out;
  };
  EXPECT_LT(gated.points_refined, ungated.points_refined);
  // Measured: across the rows 89% of the points changed ungated, 1% gated; along them 96%
  // and 60%.
  EXPECT_LT(ShareChanged(across, noisy, gated.idepth),
            0.1 * ShareChanged(across, noisy, ungated.idepth));
  EXPECT_GT(ShareChanged(along, noisy, gated.idepth),
            0.5 * ShareChanged(along, noisy, ungated.idepth));
  // What the window measures it corrects towards the truth (shape error 1.5% -> 0.9%); what
  // it cannot measure, alone, it makes worse (1.5% -> 5.4% ungated), and the gate keeps.
  const auto shape = [&](const std::vector<float>& v, const std::vector<std::size_t>& points) {
    return ShapeError(subset(v, points), subset(truth_, points));
  };
  EXPECT_LT(shape(gated.idepth, along), 0.7 * shape(noisy, along));
  EXPECT_GT(shape(ungated.idepth, across), 2.0 * shape(noisy, across));
  EXPECT_LT(shape(gated.idepth, across), 1.1 * shape(noisy, across));
}

/// Runs the pipeline on `dataset` with `system` and returns its ATE in % of path.
double RunAtePercent(const std::string& dataset, const std::string& out,
                     const SystemOptions& system) {
  RunOptions run;
  run.dataset = dataset;
  run.out_dir = out;
  run.system = system;
  RunDataset(run);
  return Evaluate(ReadTumTrajectory(out + "/trajectory.txt"),
                  ReadTumTrajectory(dataset + "/groundtruth.txt"), {})
      .ate_rmse_percent_of_path;
}

/// Renders a sequence into `folder`.
void Render(const std::string& folder, const std::string& scene, const std::string& motion,
            int frames, std::uint64_t seed) {
  synth::SynthOptions options;
  options.scene = scene;
  options.motion = motion;
  options.frames = frames;
  options.seed = seed;
  synth::WriteSyntheticSequence(options, folder);
}

TEST(StartRefinement, ImprovesAHandHeldStart) {
  // Seed 3, the judging set's hand-held room (docs/benchmarks.md, "Start refinement"), from
  // random depth: 1.37% of path, refined 0.22%. The automatic start keeps the two-view pair
  // here since 2026-12-03 (0.31%, refined 0.23%). Seed 2 is not improved: its start is
  // replaced by the two-view pair, a path the refinement does not take yet (0.288% either
  // way).
  const test::TempDirAt dir("parallax_start_refinement");
  Render(dir.File("seq"), "room", "shake", 90, 3);
  SystemOptions system;
  system.initialization = Initialization::kRandom;
  const double off = RunAtePercent(dir.File("seq"), dir.File("off"), system);
  system.start_refinement.enabled = true;
  const double on = RunAtePercent(dir.File("seq"), dir.File("on"), system);
  RecordProperty("ate_percent_off", std::to_string(off));
  RecordProperty("ate_percent_on", std::to_string(on));
  EXPECT_LT(on, 0.5 * off);
}

TEST(KeyframeRefinementInThePipeline, RefiningEveryKeyframeImprovesALongOrbitDeterministically) {
  // A 300-frame desk orbit, where refining every keyframe helped most in every variant tried
  // (docs/benchmarks.md, "Refining every keyframe": 0.50% of path without, 0.09-0.18% with);
  // its effect on other orbits is mixed, which is why it is off by default. Most of the
  // orbit's keyframes have windows long enough to be refined.
  const test::TempDirAt dir("parallax_keyframe_refinement");
  Render(dir.File("seq"), "desk", "orbit", 300, 1);
  SystemOptions system;
  const double off = RunAtePercent(dir.File("seq"), dir.File("off"), system);
  system.keyframe_refinement.enabled = true;
  const double on = RunAtePercent(dir.File("seq"), dir.File("on"), system);
  RecordProperty("ate_percent_off", std::to_string(off));
  RecordProperty("ate_percent_on", std::to_string(on));
  EXPECT_LT(on, 0.6 * off);
  // Bit-identical run to run, over the whole orbit's keyframes.
  RunAtePercent(dir.File("seq"), dir.File("again"), system);
  for (const char* file : {"trajectory.txt", "keyframes.txt"}) {
    std::ifstream a(dir.File("on") + "/" + file), b(dir.File("again") + "/" + file);
    const std::string text_a((std::istreambuf_iterator<char>(a)), {});
    const std::string text_b((std::istreambuf_iterator<char>(b)), {});
    EXPECT_FALSE(text_a.empty());
    EXPECT_EQ(text_a, text_b) << file;
  }
}

}  // namespace
}  // namespace parallax
