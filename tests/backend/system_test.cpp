// End-to-end runs of the pipeline (System via RunDataset) on rendered sequences and the shared
// TUM clip, determinism, and bad input.

#include "backend/system.hpp"

#include <gtest/gtest.h>

#include <fstream>
#include <sstream>
#include <vector>

#include "core/angles.hpp"
#include "tests/tools/temp_dir.hpp"
#include "tests/tracking/render_fixture.hpp"
#include "tools/dataset/groundtruth_files.hpp"
#include "tools/dataset/input_error.hpp"
#include "tools/dataset/trajectory.hpp"
#include "tools/eval/evaluation.hpp"
#include "tools/run_pipeline.hpp"
#include "tools/synth/renderer.hpp"
#include "tools/synth/scene.hpp"
#include "tools/synth/synthetic_sequence.hpp"

namespace parallax {
namespace {

using test::ReadFile;

class PipelineTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = std::make_unique<test::TempDirAt>("parallax_pipeline_test");
    synth::SynthOptions options;
    options.scene = "room";
    options.motion = "shake";
    options.frames = 60;
    synth::WriteSyntheticSequence(options, dir_->File("room"));
  }
  static void TearDownTestSuite() { dir_.reset(); }
  static inline std::unique_ptr<test::TempDirAt> dir_;
};

TEST_F(PipelineTest, RenderedRoomIsTrackedCompletelyAndAccurately) {
  RunOptions run;
  run.dataset = dir_->File("room");
  run.out_dir = dir_->File("out1");
  const RunSummary s = RunDataset(run);
  EXPECT_EQ(s.frames, 60);
  EXPECT_EQ(s.frames_tracked, 60);
  EXPECT_GE(s.initialised_at_frame, 0);
  const EvaluationReport r = Evaluate(ReadTumTrajectory(run.out_dir + "/trajectory.txt"),
                                      ReadTumTrajectory(run.dataset + "/groundtruth.txt"), {});
  RecordProperty("ate_percent_of_path", std::to_string(r.ate_rmse_percent_of_path));
  EXPECT_EQ(r.matched, 60u);
  EXPECT_LT(r.ate_rmse_percent_of_path, 1.0);
  for (const char* file : {"/keyframes.txt", "/map.ply", "/stats.json"}) {
    EXPECT_FALSE(ReadFile(run.out_dir + file).empty()) << file;
  }
  EXPECT_NE(ReadFile(run.out_dir + "/stats.json").find("\"frames_tracked\": 60"),
            std::string::npos);
}

TEST_F(PipelineTest, DeterministicOutput) {
  RunOptions a, b;
  a.dataset = b.dataset = dir_->File("room");
  a.max_frames = b.max_frames = 45;  // past initialisation (frame ~31) and its start selection
  a.out_dir = dir_->File("det_a");
  b.out_dir = dir_->File("det_b");
  RunDataset(a);
  RunDataset(b);
  EXPECT_EQ(ReadFile(a.out_dir + "/trajectory.txt"), ReadFile(b.out_dir + "/trajectory.txt"));
  EXPECT_EQ(ReadFile(a.out_dir + "/map.ply"), ReadFile(b.out_dir + "/map.ply"));
}

struct RenderedCase {
  const char* scene;
  const char* motion;
  Initialization initialization;
  bool exposure;
  std::uint64_t seed = 1;
  int pair_refine_stride = SystemOptions{}.pair_refine_stride;
};

/// 90 rendered frames of `c`, run with its initialisation; returns ATE as % of path length.
double RunRendered(const RenderedCase& c, RunSummary* summary) {
  const test::TempDirAt dir(std::string("parallax_pipeline_") + c.scene + "_" + c.motion);
  synth::SynthOptions synth_options;
  synth_options.scene = c.scene;
  synth_options.motion = c.motion;
  synth_options.frames = 90;
  synth_options.seed = c.seed;
  synth_options.exposure = c.exposure;
  synth_options.noise_sigma = c.exposure ? 2.0 : 0.0;
  synth::WriteSyntheticSequence(synth_options, dir.File("seq"));
  RunOptions run;
  run.dataset = dir.File("seq");
  run.out_dir = dir.File("out");
  run.system.initialization = c.initialization;
  run.system.pair_refine_stride = c.pair_refine_stride;
  *summary = RunDataset(run);
  return Evaluate(ReadTumTrajectory(run.out_dir + "/trajectory.txt"),
                  ReadTumTrajectory(run.dataset + "/groundtruth.txt"), {})
      .ate_rmse_percent_of_path;
}

class RenderedMotion : public ::testing::TestWithParam<RenderedCase> {};

TEST_P(RenderedMotion, TracksEveryFrameWithinOnePercentOfPath) {
  // Forward walk and orbit are the motions a random-depth start gets wrong (3.6% and 12.7%
  // of path with random alone); the automatic start replaces it by the two-view pair there.
  // Measured (2026-12-01): walk 0.58%, orbit 0.91%, exposure and noise 0.13% (auto) and
  // 0.30% (two-view only).
  RunSummary s;
  const double ate_percent = RunRendered(GetParam(), &s);
  RecordProperty("ate_percent_of_path", std::to_string(ate_percent));
  EXPECT_EQ(s.frames_tracked, 90);
  EXPECT_GT(s.initialised_at_frame, 0);
  EXPECT_LT(ate_percent, 1.0);
}

INSTANTIATE_TEST_SUITE_P(
    Pipeline, RenderedMotion,
    ::testing::Values(RenderedCase{"corridor", "walk", Initialization::kAuto, false},
                      RenderedCase{"room", "orbit", Initialization::kAuto, false},
                      RenderedCase{"room", "shake", Initialization::kAuto, true},
                      RenderedCase{"room", "shake", Initialization::kTwoView, true}),
    [](const ::testing::TestParamInfo<RenderedCase>& param_info) {
      const RenderedCase& c = param_info.param;
      return std::string(c.scene) + "_" + c.motion +
             (c.initialization == Initialization::kTwoView ? "_two_view" : "_auto") +
             (c.exposure ? "_exposure" : "");
    });

// When the start completes, the frames it saw are tracked again on the refined map from their
// poses then. A coarse-to-fine run from such a pose can end in another basin and still be "ok":
// on this corridor walk (with the depth filter's rotation_sigma at 0.02, where it was found)
// frame 19 ended 10 cm, 2.9% of the path, off. Se3Tracker::Refine keeps the pose refined on the
// finest level when that explains clearly more of the map: worst frame 0.24% of the path.
TEST(Pipeline, FramesTrackedAgainAtTheStartKeepTheirPoses) {
  const test::TempDirAt dir("parallax_pipeline_retrack");
  synth::SynthOptions synth_options;
  synth_options.scene = "corridor";
  synth_options.motion = "walk";
  synth_options.frames = 90;
  synth_options.seed = 3;
  synth::WriteSyntheticSequence(synth_options, dir.File("seq"));
  RunOptions run;
  run.dataset = dir.File("seq");
  run.out_dir = dir.File("out");
  run.system.depth.rotation_sigma = 0.02f;
  const RunSummary s = RunDataset(run);
  const EvaluationReport r = Evaluate(ReadTumTrajectory(run.out_dir + "/trajectory.txt"),
                                      ReadTumTrajectory(run.dataset + "/groundtruth.txt"), {});
  const double worst_percent = 100.0 * r.ate.max / r.groundtruth_path_length;
  RecordProperty("worst_frame_percent_of_path", std::to_string(worst_percent));
  EXPECT_EQ(s.frames_tracked, 90);
  EXPECT_LT(worst_percent, 0.5);
}

// The pair's start is refined by every stride-th buffered frame, counted back from the newest,
// which tracking goes on from and which must always refine.
TEST(SystemOptions, ThePairIsRefinedByEveryStrideThFrameCountedFromTheNewest) {
  SystemOptions options;
  auto refining = [&options](std::size_t buffered) {
    std::vector<std::size_t> indices;
    for (std::size_t i = 0; i < buffered + 2; ++i) {
      if (options.PairRefinesWith(i, buffered)) indices.push_back(i);
    }
    return indices;
  };
  options.pair_refine_stride = 1;
  EXPECT_EQ(refining(4), (std::vector<std::size_t>{0, 1, 2, 3}));
  options.pair_refine_stride = 2;
  EXPECT_EQ(refining(5), (std::vector<std::size_t>{0, 2, 4}));
  EXPECT_EQ(refining(4), (std::vector<std::size_t>{1, 3}));
  EXPECT_EQ(refining(1), (std::vector<std::size_t>{0}));
  EXPECT_TRUE(refining(0).empty());
  options.pair_refine_stride = 3;
  EXPECT_EQ(refining(7), (std::vector<std::size_t>{0, 3, 6}));
  EXPECT_EQ(refining(6), (std::vector<std::size_t>{2, 5}));
  options.pair_refine_stride = 0;
  EXPECT_THROW(options.Check(), std::invalid_argument);
}

// The keyframe rule: a keyframe needs min_frames_per_keyframe frames, unless the view is
// leaving it (fewer than early_keyframe_usage of its points in view) on a consistent frame.
TEST(SystemOptions, AKeyframeComesEarlyOnlyWhenAConsistentViewLeavesIt) {
  SystemOptions options;
  TrackingStats leaving;
  leaving.usage = 0.2;
  leaving.good_ratio = 0.95;
  const int second = options.min_frames_per_keyframe - 1;
  EXPECT_TRUE(options.WantsKeyframe(second, 0.0, 0.0, leaving));
  TrackingStats degraded = leaving;  // degrades the view, but a third of it is still there
  degraded.usage = 0.5;
  EXPECT_FALSE(options.WantsKeyframe(second, 0.0, 0.0, degraded));
  EXPECT_TRUE(options.WantsKeyframe(options.min_frames_per_keyframe, 0.0, 0.0, degraded));
  TrackingStats inconsistent = leaving;  // the pose itself is in doubt: wait
  inconsistent.good_ratio = 0.6;
  EXPECT_FALSE(options.WantsKeyframe(second, 0.0, 0.0, inconsistent));
  TrackingStats steady = leaving;  // a well-covered view far enough away: the usual rule
  steady.usage = 0.9;
  EXPECT_FALSE(options.WantsKeyframe(second, 1.0, 0.0, steady));
  EXPECT_TRUE(options.WantsKeyframe(options.min_frames_per_keyframe, 1.0, 0.0, steady));
  options.early_keyframe_usage = 0.0;
  EXPECT_FALSE(options.WantsKeyframe(second, 0.0, 0.0, leaving));
  options.early_keyframe_usage = 1.0;
  EXPECT_THROW(options.Check(), std::invalid_argument);
}

// The turn criterion: a frame turned past it from its keyframe, fast enough, wants a new one
// (after min_frames_per_keyframe), whatever its distance and view; 0 turns it off.
TEST(SystemOptions, AFrameTurnedPastTheRotationBoundWantsAKeyframe) {
  SystemOptions options;
  TrackingStats steady;
  steady.usage = 0.9;
  steady.good_ratio = 0.95;
  const int enough = options.min_frames_per_keyframe;
  EXPECT_TRUE(options.WantsKeyframe(enough, 0.0, options.keyframe_rotation_deg + 1.0, steady));
  // The same angle reached slowly (below keyframe_rotation_min_rate_deg a frame) is left to
  // the usage rule; a rate of 0 counts every turn.
  const double angle = options.keyframe_rotation_deg + 1.0;
  const int slow = static_cast<int>(angle / options.keyframe_rotation_min_rate_deg) + 1;
  EXPECT_FALSE(options.WantsKeyframe(slow, 0.0, angle, steady));
  EXPECT_TRUE(options.WantsKeyframe(slow - 1, 0.0, angle, steady));
  options.keyframe_rotation_min_rate_deg = 0.0;
  EXPECT_TRUE(options.WantsKeyframe(slow, 0.0, angle, steady));
  options.keyframe_rotation_min_rate_deg = -1.0;
  EXPECT_THROW(options.Check(), std::invalid_argument);
  options.keyframe_rotation_min_rate_deg = 0.0;
  options.keyframe_rotation_deg = 0.0;
  EXPECT_FALSE(options.WantsKeyframe(enough, 0.0, 90.0, steady));  // off: a turn is no distance
  options.keyframe_rotation_deg = 25.0;
  EXPECT_FALSE(options.WantsKeyframe(enough, 0.0, 24.0, steady));
  EXPECT_TRUE(options.WantsKeyframe(enough, 0.0, 26.0, steady));
  EXPECT_FALSE(options.WantsKeyframe(enough - 1, 0.0, 26.0, steady));
  // The angle of R_kf_frame, whichever its axis.
  const SE3d turned(SO3d::Exp(Eigen::Vector3d(0.0, 30.0 / kRadToDeg, 0.0)),
                    Eigen::Vector3d::Zero());
  EXPECT_NEAR(SystemOptions::RotationDeg(turned), 30.0, 1e-9);
  EXPECT_NEAR(SystemOptions::RotationDeg(turned.Inverse()), 30.0, 1e-9);
  options.keyframe_rotation_deg = -1.0;
  EXPECT_THROW(options.Check(), std::invalid_argument);
}

TEST(Pipeline, AutoStartKeepsThePairWhenTheGeometryAgrees) {
  // Desk shake, seed 4: the random start converges to a depth that agrees with the pair's
  // geometry and explains the buffered frames almost as well (residual ratio 0.93), but its
  // trajectory is ten times worse. Measured 2026-12-03: 0.057% of path with the pair kept,
  // 0.64% when the start kept the random depth (the former residual comparison, 0.9).
  RunSummary s;
  const double ate_percent =
      RunRendered(RenderedCase{"desk", "shake", Initialization::kAuto, false, 4}, &s);
  RecordProperty("ate_percent_of_path", std::to_string(ate_percent));
  EXPECT_EQ(s.frames_tracked, 90);
  EXPECT_LT(ate_percent, 0.2);
}

TEST(Pipeline, ThePairRefinedByEveryOtherBufferedFrameIsMoreAccurate) {
  // Desk shake, seed 4, a judging sequence of pair_refine_stride (docs/configuration.md,
  // "Choosing the initialisation"). Measured 2026-12-06: 0.057% of path with every frame,
  // 0.022% with every second.
  RunSummary every, every_other;
  const double every_percent =
      RunRendered(RenderedCase{"desk", "shake", Initialization::kAuto, false, 4, 1}, &every);
  const double every_other_percent =
      RunRendered(RenderedCase{"desk", "shake", Initialization::kAuto, false, 4, 2}, &every_other);
  RecordProperty("ate_percent_every_frame", std::to_string(every_percent));
  RecordProperty("ate_percent_every_other_frame", std::to_string(every_other_percent));
  EXPECT_EQ(every.frames_tracked, 90);
  EXPECT_EQ(every_other.frames_tracked, 90);
  EXPECT_LT(every_other_percent, 0.6 * every_percent);
}

/// The rendered room seen from its start pose moved by T_start_c (TestCamera(), which is the
/// synthetic camera), times `gain`, plus Gaussian noise.
ImageU8 RenderRoom(const SE3d& T_start_c, float gain, double noise_sigma, std::uint64_t seed) {
  static const synth::Scene scene = synth::MakeScene("room", 1);
  return test::RenderTestImage(scene, synth::FramePose({}, scene, 0) * T_start_c, gain, noise_sigma,
                               seed);
}

/// 60 frames of a sideways pan through the rendered room (1.2 m, 36 degrees), then a jump
/// back to 2-8 cm from the start (as after a dropped stretch of video); returns how many of
/// the 10 frames after the jump were tracked, checking their rotations.
int TrackedAfterJumpBack(int recent_keyframes, bool relocalization = false) {
  SystemOptions options;
  options.recent_keyframes = recent_keyframes;
  options.relocalization.enabled = relocalization;
  System system(synth::SynthCamera({}), options);
  auto render = [](const SE3d& T_start_c) { return RenderRoom(T_start_c, 1.0f, 0.0, 1); };
  auto pan = [](double i) {  // 2 cm and 0.6 degrees per frame, with a little bob
    return SE3d(SO3d::Exp(Eigen::Vector3d(0.0, 0.0105 * i, 0.0)),
                Eigen::Vector3d(0.02 * i, 0.004 * std::sin(0.7 * i), 0.0));
  };
  int frame = 0;
  for (; frame < 60; ++frame) system.ProcessFrame(render(pan(frame)), frame / 30.0);
  EXPECT_GE(system.Keyframes().size(), 3u);
  int tracked = 0;
  for (int k = 0; k < 10; ++k, ++frame) {
    const SE3d T_start_c = pan(1.0 + 0.3 * k);
    const FrameResult r = system.ProcessFrame(render(T_start_c), frame / 30.0);
    if (!r.T_w_c) continue;
    ++tracked;
    // World = the first keyframe = the start pose: rotations compare directly. Measured
    // 0.3-0.6 degrees (the random start's depth is not exact); a wrong similarity chain
    // when switching keyframes would be off by the 36 degree pan.
    const double rotation_error =
        (r.T_w_c->Rotation().Inverse() * T_start_c.Rotation()).Log().norm();
    EXPECT_LT(rotation_error, 0.02) << "frame " << frame;
  }
  return tracked;
}

TEST(Pipeline, LostFramesAreRecoveredOnRecentKeyframes) {
  // The jump back is far outside what the motion hypotheses around the last pose reach, so
  // only an earlier keyframe recovers it; without recent keyframes (and without
  // relocalisation) every later frame is lost, and relocalisation alone recovers them too.
  EXPECT_GE(TrackedAfterJumpBack(4), 9);
  EXPECT_EQ(TrackedAfterJumpBack(0), 0);
  EXPECT_GE(TrackedAfterJumpBack(0, true), 9);
}

TEST(Pipeline, StaticCameraInventsNoMotionAndNoKeyframes) {
  System system(synth::SynthCamera({}));
  for (int i = 0; i < 200; ++i) {
    const FrameResult r = system.ProcessFrame(
        RenderRoom(SE3d(), 1.0f, 2.0, 100u + static_cast<std::uint64_t>(i)), i / 30.0);
    ASSERT_TRUE(r.T_w_c.has_value()) << "frame " << i;
    EXPECT_LT(r.T_w_c->Translation().norm(), 0.003) << "frame " << i;
  }
  EXPECT_EQ(system.Keyframes().size(), 1u);
  EXPECT_EQ(system.InitialisedAtFrame(), -1);  // no parallax yet: nothing to initialise from
}

TEST(Pipeline, DarkStartGivesNoPosesThenInitialises) {
  // 20 frames with the lens covered (grey level ~3 and noise), then hand-held shake.
  synth::SynthOptions shake;
  shake.frames = 60;
  const synth::Scene scene = synth::MakeScene("room", 1);
  const SE3d T_w_start = synth::FramePose(shake, scene, 0);
  System system(synth::SynthCamera(shake));
  std::vector<std::optional<SE3d>> poses;
  for (int i = 0; i < 80; ++i) {
    const bool dark = i < 20;
    const SE3d T_start_c =
        dark ? SE3d() : T_w_start.Inverse() * synth::FramePose(shake, scene, i - 20);
    const FrameResult r = system.ProcessFrame(
        RenderRoom(T_start_c, dark ? 0.02f : 1.0f, 1.0, static_cast<std::uint64_t>(i)), i / 30.0);
    poses.push_back(r.T_w_c);
    for (const RevisedPose& revised : r.revised) {
      poses[static_cast<std::size_t>(revised.frame_id)] = revised.T_w_c;
    }
  }
  for (int i = 0; i < 20; ++i) EXPECT_FALSE(poses[static_cast<std::size_t>(i)]) << "frame " << i;
  int tracked = 0;
  for (int i = 20; i < 80; ++i) tracked += poses[static_cast<std::size_t>(i)] ? 1 : 0;
  EXPECT_GE(tracked, 50);
  EXPECT_GE(system.InitialisedAtFrame(), 20);
}

TEST(Pipeline, PureRotationKeepsThePositionAndTheMap) {
  // 30 frames 30 cm sideways, 30 frames turning in place (up to 34 degrees), 30 sideways.
  synth::SynthOptions rotate;
  rotate.motion = "rotate";
  rotate.frames = 90;
  const synth::Scene scene = synth::MakeScene("room", 1);
  const SE3d T_w_start = synth::FramePose(rotate, scene, 0);
  System system(synth::SynthCamera(rotate));
  std::vector<SE3d> truth;
  std::vector<std::optional<SE3d>> poses;
  for (int i = 0; i < rotate.frames; ++i) {
    truth.push_back(T_w_start.Inverse() * synth::FramePose(rotate, scene, i));
    const FrameResult r =
        system.ProcessFrame(RenderRoom(truth.back(), 1.0f, 1.0, static_cast<std::uint64_t>(i)),
                            synth::FrameTimestamp(rotate, i));
    poses.push_back(r.T_w_c);
    for (const RevisedPose& revised : r.revised) {
      poses[static_cast<std::size_t>(revised.frame_id)] = revised.T_w_c;
    }
  }
  for (int i = 0; i < rotate.frames; ++i) ASSERT_TRUE(poses[static_cast<std::size_t>(i)]) << i;
  // Position: still while turning, relative to the first leg's length (scale is free).
  const double leg = (poses[30]->Translation() - poses[0]->Translation()).norm();
  for (int i = 31; i < 60; ++i) {
    EXPECT_LT((poses[static_cast<std::size_t>(i)]->Translation() - poses[30]->Translation()).norm(),
              0.1 * leg)
        << "frame " << i;
  }
  // The turn itself, relative to where it began: the start's own error (below) cancels.
  const SE3d T_30_true = truth[30];
  for (int i : {40, 45, 50, 60}) {
    const auto k = static_cast<std::size_t>(i);
    const SO3d turn = poses[30]->Rotation().Inverse() * poses[k]->Rotation();
    const SO3d turn_true = T_30_true.Rotation().Inverse() * truth[k].Rotation();
    EXPECT_LT((turn.Inverse() * turn_true).Log().norm(), 0.01) << "frame " << i;
  }
  // The whole run against the truth (world = start pose): the first leg is purely sideways,
  // where a random start converges to a distorted depth (2 degrees and ~30 degrees of
  // direction error); the automatic start keeps the two-view start there. Measured 0.17 and
  // 0.49 degrees, direction within 1 degree, second leg 0.95 of the first.
  for (int i : {30, 89}) {
    const auto k = static_cast<std::size_t>(i);
    EXPECT_LT((poses[k]->Rotation().Inverse() * truth[k].Rotation()).Log().norm(), 0.015)
        << "frame " << i;
  }
  const Eigen::Vector3d leg_true = truth[30].Translation() - truth[0].Translation();
  const Eigen::Vector3d leg_estimated = poses[30]->Translation() - poses[0]->Translation();
  EXPECT_GT(leg_true.normalized().dot(leg_estimated.normalized()), std::cos(0.05));
  const double second_leg = (poses[89]->Translation() - poses[60]->Translation()).norm();
  EXPECT_NEAR(second_leg / leg, 1.0, 0.1);
  EXPECT_LE(system.Keyframes().size(), 8u);  // no keyframe per rotated frame
}

/// A run of one of ../shared/data's clips with its outputs in `dir`.
RunOptions SharedClipRun(const std::string& clip, const test::TempDirAt& dir) {
  RunOptions run;
  run.dataset = test::SharedDataDir() + "/" + clip;
  run.out_dir = dir.File("out");
  return run;
}

TEST(Pipeline, SharedTumClip) {
  if (test::SharedDataDir().empty())
    GTEST_SKIP() << "../shared/data is absent; TUM end-to-end test skipped";
  const test::TempDirAt dir("parallax_pipeline_tum");
  const RunOptions run = SharedClipRun("rgbd_dataset_freiburg1_xyz_first37", dir);
  const RunSummary s = RunDataset(run);
  const EvaluationReport r = Evaluate(ReadTumTrajectory(run.out_dir + "/trajectory.txt"),
                                      ReadTumTrajectory(run.dataset + "/groundtruth.txt"), {});
  RecordProperty("ate_m", std::to_string(r.ate.rmse));
  // Measured 37/37 frames and 5.1 mm (5.955 mm before the two-view start's homography gate);
  // the bound is issue 13's.
  EXPECT_EQ(s.frames_tracked, 37);
  EXPECT_LT(r.ate.rmse, 0.0059);
  // The orientation, which the ATE of positions does not see: measured 1.0 degree rms over
  // 1 s steps (13 degrees when the start took the plane's twin solution of its pair).
  EXPECT_LT(r.rpe_per_second.rotation_deg.rmse, 3.0);
  // The camera moves from the first frame on: the start must complete within its first
  // second (30 frames; measured: frame 20).
  EXPECT_GE(s.initialised_at_frame, 0);
  EXPECT_LT(s.initialised_at_frame, 30);
}

// The KITTI clip from its second frame: the two-view pair's parallax peaks at 1.95 degrees
// (frame 11, the bound is 2) and then falls as the near points leave the view, and the
// random start is lost at frame 18. Before the fallback pair, six lost frames restarted the
// start (at 24, 37, 54), withdrawing every pose: 7 of these 60 frames were posed.
TEST(Pipeline, AForwardStartShortOfParallaxStartsFromItsBestPair) {
  if (test::SharedDataDir().empty())
    GTEST_SKIP() << "../shared/data is absent; KITTI start test skipped";
  const test::TempDirAt dir("parallax_pipeline_kitti_start");
  RunOptions run = SharedClipRun("kitti_odometry_07_first160", dir);
  run.first_frame = 1;
  run.max_frames = 60;
  const RunSummary s = RunDataset(run);
  EXPECT_EQ(s.frames_tracked, 60);
  EXPECT_GE(s.initialised_at_frame, 0);
  EXPECT_LT(s.initialised_at_frame, 24);  // measured 18: the first lost frame
  const EvaluationReport r = Evaluate(ReadTumTrajectory(run.out_dir + "/trajectory.txt"),
                                      ReadDatasetGroundTruth(run.dataset).poses, {});
  RecordProperty("ate_percent_of_path", std::to_string(r.ate_rmse_percent_of_path));
  EXPECT_LT(r.ate_rmse_percent_of_path, 1.5);  // measured 0.81% (22 m)
}

TEST(Pipeline, BadInputIsReportedWithTheFileName) {
  const test::TempDirAt dir("parallax_pipeline_bad");
  RunOptions run;
  run.out_dir = dir.File("out");
  run.dataset = dir.File("missing");
  EXPECT_THROW(RunDataset(run), InputError);
  std::filesystem::create_directories(dir.File("empty"));
  run.dataset = dir.File("empty");
  EXPECT_THROW(RunDataset(run), InputError);
  // A TUM folder whose image is corrupt.
  std::filesystem::create_directories(dir.File("corrupt/rgb"));
  std::ofstream(dir.File("corrupt/rgb.txt")) << "1.0 rgb/a.png\n";
  std::ofstream(dir.File("corrupt/rgb/a.png")) << "not a png";
  std::ofstream(dir.File("corrupt/calibration.yaml"))
      << "model: pinhole\nwidth: 64\nheight: 48\nfx: 50\nfy: 50\ncx: 31.5\ncy: 23.5\n";
  run.dataset = dir.File("corrupt");
  // By default the frame is skipped and reported; nothing is posed.
  const RunSummary skipped = RunDataset(run);
  EXPECT_EQ(skipped.frames_unreadable, 1);
  EXPECT_EQ(skipped.frames_tracked, 0);
  run.fatal_unreadable = true;
  try {
    RunDataset(run);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("a.png"), std::string::npos) << e.what();
  }
  // fx = 0 in the calibration.
  std::ofstream(dir.File("corrupt/calibration.yaml"))
      << "model: pinhole\nwidth: 64\nheight: 48\nfx: 0\nfy: 50\ncx: 31.5\ncy: 23.5\n";
  try {
    RunDataset(run);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("fx"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace parallax
