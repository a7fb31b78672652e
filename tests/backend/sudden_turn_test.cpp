// A sudden turn, end to end: the rendered street patrol goes from walking straight to 11.8
// degrees of yaw per frame between two frames (10 frames/s). The constant-velocity start
// leaves the first frames of the turn in a wrong basin that still explains most points; the
// tracker's suspect-result search (Se3TrackerOptions::suspect_good_ratio) must find the right one,
// and without it the same run must fail, so the scene really tests it. Where the run goes after
// the turn depends on the map's last digits (docs/benchmarks.md, "A sudden turn"), so the
// turn's own steps are what is checked, with the default settings and with one nudged.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "tests/tools/temp_dir.hpp"
#include "tools/dataset/trajectory.hpp"
#include "tools/eval/evaluation.hpp"
#include "tools/run_pipeline.hpp"
#include "tools/synth/synthetic_sequence.hpp"

namespace parallax {
namespace {

struct TurnRun {
  double ate_percent = 0.0;
  double worst_step_rotation_deg = 0.0;  ///< frame-to-frame rotation error, frames 95-110
  std::size_t posed = 0;
};

TurnRun RunTurn(const std::string& dataset, const std::string& out, const SystemOptions& system) {
  RunOptions run;
  run.dataset = dataset;
  run.out_dir = out;
  run.first_frame = 70;  // 30 frames of straight walking to start on, then the U-turn
  run.system = system;
  RunDataset(run);
  const Trajectory estimate = ReadTumTrajectory(out + "/trajectory_online.txt");
  const Trajectory truth = ReadTumTrajectory(dataset + "/groundtruth.txt");
  TurnRun result;
  result.posed = estimate.size();
  result.ate_percent =
      Evaluate(ReadTumTrajectory(out + "/trajectory.txt"), truth, {}).ate_rmse_percent_of_path;
  for (std::size_t k = 0; k + 1 < estimate.size(); ++k) {
    const auto frame = static_cast<std::size_t>(std::lround(estimate[k].timestamp * 10.0));
    if (frame < 95 || frame > 110) continue;
    const SE3d step = estimate[k].T_w_c.Inverse() * estimate[k + 1].T_w_c;
    const SE3d true_step = truth[frame].T_w_c.Inverse() * truth[frame + 1].T_w_c;
    const double error = (true_step.Rotation().Inverse() * step.Rotation()).Log().norm();
    result.worst_step_rotation_deg = std::max(result.worst_step_rotation_deg, error * 57.29578);
  }
  return result;
}

TEST(SuddenTurn, TheSuspectResultSearchTracksTheFirstFramesOfAUTurn) {
  const test::TempDirAt dir("parallax_sudden_turn");
  synth::SynthOptions options;
  options.scene = "street";
  options.motion = "patrol";
  options.frames = 130;
  options.fps = 10.0;
  synth::WriteSyntheticSequence(options, dir.File("seq"));
  const TurnRun with = RunTurn(dir.File("seq"), dir.File("with"), SystemOptions{});
  SystemOptions nudged_options;
  nudged_options.tracker.pixel_noise_sigma = 4.01f;
  const TurnRun nudged = RunTurn(dir.File("seq"), dir.File("nudged"), nudged_options);
  SystemOptions no_search;
  no_search.tracker.suspect_good_ratio = 0.0f;
  const TurnRun without = RunTurn(dir.File("seq"), dir.File("without"), no_search);
  RecordProperty("ate_percent_with", std::to_string(with.ate_percent));
  RecordProperty("ate_percent_nudged", std::to_string(nudged.ate_percent));
  RecordProperty("ate_percent_without", std::to_string(without.ate_percent));
  RecordProperty("worst_step_deg_with", std::to_string(with.worst_step_rotation_deg));
  RecordProperty("worst_step_deg_nudged", std::to_string(nudged.worst_step_rotation_deg));
  RecordProperty("worst_step_deg_without", std::to_string(without.worst_step_rotation_deg));
  EXPECT_EQ(with.posed, 60u);
  EXPECT_EQ(nudged.posed, 60u);
  // Measured: worst steps 0.81 and 0.96 degrees (before the search restarted from the motion
  // model's translation 1.10 and 0.40, the turn's first two steps 1.06 and 1.10 off); ATE
  // 1.67% and 0.60% of the path (0.46% and 0.96% before). Without the search 7.6 degrees.
  EXPECT_LT(with.worst_step_rotation_deg, 1.0);
  EXPECT_LT(nudged.worst_step_rotation_deg, 1.0);
  EXPECT_LT(with.ate_percent, 2.5);
  EXPECT_LT(nudged.ate_percent, 2.5);
  EXPECT_GT(without.worst_step_rotation_deg, 3.0);
}

}  // namespace
}  // namespace parallax
