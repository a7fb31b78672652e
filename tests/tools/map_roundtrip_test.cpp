// The map round trip the C API and `parallax run --save-map/--load-map` promise, on the
// KITTI clip: a map saved after the first half, loaded by a second run over the second half,
// relocalises within 5 frames and poses agree with the uninterrupted run's to within 2x its
// ATE. Three runs of the clip (about a minute): CTest label `slow`, not run under ASan.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>

#include "tests/tools/temp_dir.hpp"
#include "tools/dataset/groundtruth_files.hpp"
#include "tools/dataset/trajectory.hpp"
#include "tools/eval/evaluation.hpp"
#include "tools/run_pipeline.hpp"

namespace parallax {
namespace {

std::string KittiClip() {
  return std::string(PARALLAX_SHARED_DATA_DIR) + "/kitti_odometry_07_first160";
}

/// Index (within the run) of the first frame whose frames.csv events name a relocalisation.
int FirstRelocalisedFrame(const std::string& frames_csv) {
  std::ifstream in(frames_csv);
  std::string line;
  std::getline(in, line);  // header
  for (int k = 0; std::getline(in, line); ++k) {
    if (line.find("relocalised:") != std::string::npos) return k;
  }
  return -1;
}

TEST(MapRoundTrip, KittiSecondHalfOnTheFirstHalfsMap) {
  if (!std::filesystem::exists(KittiClip())) GTEST_SKIP() << "../shared/data is absent";
  const test::TempDir dir;
  RunOptions single;
  single.dataset = KittiClip();
  single.out_dir = dir.File("single");
  const RunSummary all = RunDataset(single);
  RunOptions first = single;
  first.out_dir = dir.File("first");
  first.max_frames = all.frames / 2;
  first.save_map = dir.File("first.pxmap");
  RunDataset(first);
  RunOptions second = single;
  second.out_dir = dir.File("second");
  second.first_frame = all.frames / 2;
  second.load_map = first.save_map;
  const RunSummary rest = RunDataset(second);
  EXPECT_EQ(rest.frames, all.frames - all.frames / 2);
  EXPECT_EQ(rest.maps_started, 0);

  const int relocalised_at = FirstRelocalisedFrame(second.out_dir + "/frames.csv");
  RecordProperty("relocalised_at_frame", relocalised_at);
  EXPECT_GE(relocalised_at, 0);
  EXPECT_LT(relocalised_at, 5);

  // The single run's ATE, and the second run's distance from the single run's poses (the
  // same world frame: no alignment of its own) in metres through the single run's alignment.
  const Trajectory reference = ReadTumTrajectory(single.out_dir + "/trajectory.txt");
  const EvaluationReport report =
      Evaluate(reference, ReadDatasetGroundTruth(KittiClip()).poses, {});
  std::map<double, Eigen::Vector3d> by_time;
  for (const StampedPose& p : reference) by_time[p.timestamp] = p.T_w_c.Translation();
  const Trajectory loaded = ReadTumTrajectory(second.out_dir + "/trajectory.txt");
  ASSERT_GE(loaded.size(), static_cast<std::size_t>(rest.frames - 5));
  double sq = 0.0;
  for (const StampedPose& p : loaded) {
    const Eigen::Vector3d d =
        report.S_gt_est * p.T_w_c.Translation() - report.S_gt_est * by_time.at(p.timestamp);
    sq += d.squaredNorm();
  }
  const double difference = std::sqrt(sq / static_cast<double>(loaded.size()));
  RecordProperty("single_run_ate_m", std::to_string(report.ate.rmse));
  RecordProperty("difference_m", std::to_string(difference));
  EXPECT_LE(difference, 2.0 * report.ate.rmse);
}

}  // namespace
}  // namespace parallax
