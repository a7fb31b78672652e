// Loop closure end to end on rendered sequences: a full orbit closes its loop and the map
// follows; a long corridor walk (repeated textures, no revisit) closes none.

#include <gtest/gtest.h>

#include <algorithm>

#include "tests/backend/scenario_options.hpp"
#include "tests/tools/temp_dir.hpp"
#include "tools/dataset/trajectory.hpp"
#include "tools/eval/evaluation.hpp"
#include "tools/run_pipeline.hpp"
#include "tools/synth/synthetic_sequence.hpp"

namespace parallax {
namespace {

struct LoopRun {
  RunSummary summary;
  double ate_percent = 0.0;
  Trajectory final_poses;
  Trajectory online_poses;
};

LoopRun RunSequence(const test::TempDirAt& dir, const std::string& name, bool loop_closure,
                    const SystemOptions& system = {}) {
  RunOptions run;
  run.system = system;
  run.dataset = dir.File("seq");
  run.out_dir = dir.File(name);
  run.system.loop_closure.enabled = loop_closure;
  LoopRun r;
  r.summary = RunDataset(run);
  r.final_poses = ReadTumTrajectory(run.out_dir + "/trajectory.txt");
  r.online_poses = ReadTumTrajectory(run.out_dir + "/trajectory_online.txt");
  r.ate_percent = Evaluate(r.final_poses, ReadTumTrajectory(run.dataset + "/groundtruth.txt"), {})
                      .ate_rmse_percent_of_path;
  return r;
}

void Render(const test::TempDirAt& dir, const char* scene, const char* motion, int frames) {
  synth::SynthOptions options;
  options.scene = scene;
  options.motion = motion;
  options.frames = frames;
  synth::WriteSyntheticSequence(options, dir.File("seq"));
}

TEST(LoopClosure, AFullOrbitClosesItsLoopAndTheMapFollows) {
  const test::TempDirAt dir("parallax_loop_orbit");
  Render(dir, "room", "orbit", 150);
  const LoopRun with = RunSequence(dir, "with", true);
  const LoopRun without = RunSequence(dir, "without", false);
  RecordProperty("ate_percent_with", std::to_string(with.ate_percent));
  RecordProperty("ate_percent_without", std::to_string(without.ate_percent));
  EXPECT_GE(with.summary.loops_closed, 1);
  EXPECT_EQ(with.summary.edges.loop, with.summary.loops_closed);
  EXPECT_EQ(without.summary.loops_closed, 0);
  EXPECT_EQ(without.summary.loop_candidates, 0);
  EXPECT_EQ(with.summary.frames_tracked, 150);
  // Not worse than without (measured: 0.209% against 0.210%; the 150-frame orbit drifts
  // little, docs/place_recognition.md has the longer runs).
  EXPECT_LE(with.ate_percent, without.ate_percent * 1.02);
  // trajectory.txt comes from the corrected graph: frames before the loop moved.
  ASSERT_EQ(with.final_poses.size(), with.online_poses.size());
  double moved = 0.0;
  for (std::size_t i = 0; i < with.final_poses.size(); ++i) {
    moved = std::max(
        moved, (with.final_poses[i].T_w_c.Translation() - with.online_poses[i].T_w_c.Translation())
                   .norm());
  }
  EXPECT_GT(moved, 1e-3);
}

TEST(LoopClosure, AnOrbitEndingAtItsStartClosesTheLoopAtTheEndOfTheInput) {
  // Seed 4: only the last keyframe, never finished by a later one, sees the start well
  // enough twice in a row; FinishMapping puts it through the backend at the end. (With the
  // depth filter's pixel budget the loop closes before the end on this seed, 0.131% against
  // 0.163% without: the scenario is kept with every estimate observed every update, and with
  // the keyframe rule it was found with.)
  SystemOptions system = test::WithRelativeKeyframeRule();
  system.depth.converged_relative_sigma = 0.0f;
  const test::TempDirAt dir("parallax_loop_orbit_end");
  synth::SynthOptions options;
  options.scene = "room";
  options.motion = "orbit";
  options.frames = 300;
  options.seed = 4;
  synth::WriteSyntheticSequence(options, dir.File("seq"));
  const LoopRun with = RunSequence(dir, "with", true, system);
  const LoopRun without = RunSequence(dir, "without", false, system);
  RecordProperty("ate_percent_with", std::to_string(with.ate_percent));
  RecordProperty("ate_percent_without", std::to_string(without.ate_percent));
  EXPECT_NE(with.summary.end_events.find("loop:"), std::string::npos) << with.summary.end_events;
  EXPECT_GE(with.summary.loops_closed, 1);
  EXPECT_EQ(without.summary.end_events.find("loop:"), std::string::npos);
  // Measured 0.169% against 0.178% of the path.
  EXPECT_LT(with.ate_percent, without.ate_percent);
}

TEST(LoopClosure, ALongCorridorWalkClosesNoFalseLoop) {
  // The corridor's textures repeat: without the drift bound, 2 loops were accepted here
  // between places 7.6 m apart (the walk does not come back within 400 frames).
  const test::TempDirAt dir("parallax_loop_corridor");
  Render(dir, "corridor", "patrol", 400);
  // The keyframes of the rule this was measured with bring candidates to verification (with
  // the image distance's sparser ones, none gets that far on this walk).
  const LoopRun run = RunSequence(dir, "out", true, test::WithRelativeKeyframeRule());
  EXPECT_EQ(run.summary.loops_closed, 0);
  EXPECT_EQ(run.summary.edges.loop, 0);
  // The gates were exercised, not bypassed: candidates reached verification.
  EXPECT_GT(run.summary.loop_checks, 0);
  EXPECT_EQ(run.summary.loops_rejected, run.summary.loop_checks);
}

}  // namespace
}  // namespace parallax
