// Hard real input (issue 15): the TUM and KITTI clips with a very dark start and an
// over-exposed end, as an auto-exposure that starts far too low and ends far too high. Every frame
// given a pose must be right (within 3% of the matched path after alignment) and at least 40% of
// the frames must get one.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <opencv2/core.hpp>
#include <random>
#include <set>
#include <sstream>

#include "tests/tools/temp_dir.hpp"
#include "tools/dataset/groundtruth_files.hpp"
#include "tools/dataset/image_file.hpp"
#include "tools/dataset/trajectory.hpp"
#include "tools/eval/evaluation.hpp"
#include "tools/run_pipeline.hpp"

namespace parallax {
namespace {

std::string SharedClip(const std::string& name) {
  return std::string(PARALLAX_SHARED_DATA_DIR) + "/" + name;
}

// Exposure ramps: the first `dark` frames rise from `dark_start` by `dark_rate` a frame, the
// last `bright` frames from `bright_start` by `bright_rate` a frame (clipped at 255).
struct Ramps {
  int dark = 10;
  int bright = 8;
  double dark_start = 0.03, dark_rate = 1.4;
  double bright_start = 1.35, bright_rate = 1.35;
};

// Gain of frame k of n.
double Gain(int k, int n, const Ramps& ramps) {
  if (k < ramps.dark) return ramps.dark_start * std::pow(ramps.dark_rate, k);
  if (k >= n - ramps.bright) {
    return ramps.bright_start * std::pow(ramps.bright_rate, k - (n - ramps.bright));
  }
  return 1.0;
}

struct ClipImage {
  std::string file;  ///< relative to the clip's folder
  double timestamp;
};

// The images of a TUM RGB-D (rgb.txt) or KITTI odometry (sequences/NN/times.txt) clip.
std::vector<ClipImage> ClipImages(const std::string& folder) {
  std::vector<ClipImage> images;
  if (std::filesystem::exists(folder + "/rgb.txt")) {
    std::ifstream list(folder + "/rgb.txt");
    for (std::string line; std::getline(list, line);) {
      if (line.empty() || line[0] == '#') continue;
      std::istringstream fields(line);
      ClipImage image{};
      fields >> image.timestamp >> image.file;
      images.push_back(image);
    }
    return images;
  }
  const std::filesystem::path sequence =
      std::filesystem::directory_iterator(folder + "/sequences")->path();
  std::ifstream times(sequence / "times.txt");
  char name[16];
  double t = 0.0;
  for (int k = 0; times >> t; ++k) {
    std::snprintf(name, sizeof(name), "%06d.png", k);
    const std::filesystem::path file = sequence / "image_0" / name;
    images.push_back({std::filesystem::relative(file, folder).string(), t});
  }
  return images;
}

struct ExposedFrame {
  double timestamp;
  double gain;
};

// A copy of the clip with exposure applied to the images (sensor noise sigma 1.5 added).
std::vector<ExposedFrame> WriteExposedCopy(const std::string& clip, const std::string& out,
                                           const Ramps& ramps) {
  std::filesystem::copy(clip, out, std::filesystem::copy_options::recursive);
  const std::vector<ClipImage> images = ClipImages(clip);
  std::vector<ExposedFrame> exposed;
  std::mt19937 rng(5);
  std::normal_distribution<double> noise(0.0, 1.5);
  const int n = static_cast<int>(images.size());
  for (int k = 0; k < n; ++k) {
    const ClipImage& source = images[static_cast<std::size_t>(k)];
    cv::Mat image = ReadImageFile(clip + "/" + source.file, ImageReadMode::kGrey8);
    const double gain = Gain(k, n, ramps);
    for (int y = 0; y < image.rows; ++y) {
      for (int x = 0; x < image.cols; ++x) {
        const double v = gain * image.at<std::uint8_t>(y, x) + noise(rng);
        image.at<std::uint8_t>(y, x) =
            static_cast<std::uint8_t>(std::clamp(std::lround(v), 0L, 255L));
      }
    }
    WritePngFile(out + "/" + source.file, image);
    exposed.push_back({source.timestamp, gain});
  }
  return exposed;
}

struct HardRun {
  double share_posed = 0.0;
  double worst_percent = 0.0;            ///< worst posed frame's error, % of the matched path
  std::vector<int> posed_without_light;  ///< frames below 10% or above 2x exposure with a pose
};

// Runs the exposed copy of `clip` (written as `name`, which tells the camera) and measures it.
HardRun RunExposed(const std::string& clip, const std::string& name, const Ramps& ramps) {
  const test::TempDir dir;
  const auto frames = WriteExposedCopy(clip, dir.File(name), ramps);
  RunOptions run;
  run.dataset = dir.File(name);
  run.out_dir = dir.File("out");
  const RunSummary summary = RunDataset(run);
  const Trajectory estimate = ReadTumTrajectory(run.out_dir + "/trajectory.txt");
  const EvaluationReport report =
      Evaluate(estimate, ReadDatasetGroundTruth(run.dataset).poses, EvaluationOptions{});
  HardRun result;
  result.share_posed = static_cast<double>(summary.frames_tracked) / summary.frames;
  result.worst_percent = 100.0 * report.ate.max / report.groundtruth_path_length;
  std::set<double> posed;
  for (const auto& p : estimate) posed.insert(std::round(p.timestamp * 1e4));
  for (std::size_t k = 0; k < frames.size(); ++k) {
    const bool without_light = frames[k].gain < 0.1 || frames[k].gain > 2.0;
    if (without_light && posed.count(std::round(frames[k].timestamp * 1e4)) > 0) {
      result.posed_without_light.push_back(static_cast<int>(k));
    }
  }
  return result;
}

// Records a run's share posed and worst error in the test's XML output.
void RecordResult(const HardRun& r) {
  ::testing::Test::RecordProperty("share_posed", std::to_string(r.share_posed));
  ::testing::Test::RecordProperty("worst_error_percent_of_path", std::to_string(r.worst_percent));
}

// Issue 15's bounds for hard input: at least 40% posed, every posed frame within 3% of the
// matched path, and nothing claimed for the frames with almost no light or almost all
// saturated.
void ExpectWithinIssue15Bounds(const HardRun& r) {
  EXPECT_GE(r.share_posed, 0.4);
  EXPECT_LE(r.worst_percent, 3.0);
  EXPECT_TRUE(r.posed_without_light.empty()) << "first: frame " << r.posed_without_light[0];
}

TEST(HardExposure, DarkStartAndBlownOutEndArePosedRightOrNotAtAll) {
  const HardRun r = RunExposed(SharedClip("rgbd_dataset_freiburg1_xyz_first37"),
                               "rgbd_dataset_freiburg1_xyz", Ramps{});
  RecordResult(r);
  // Measured: 20 of 37 posed (frames 10-29: the start restarts twice while the exposure
  // settles), ATE 3.1 mm, worst 2.3% of the matched path (8.8% before the two-view start
  // refused ambiguous pairs; docs/reliability.md). The bound is issue 15's.
  ExpectWithinIssue15Bounds(r);
}

// Other ramps on the TUM clip, measured when the defaults were already chosen (a held-out
// variant): 9 dark frames from 3% rising 45% a frame, 7 bright from 1.4x rising 40%.
TEST(HardExposure, AnotherDarkStartAndBlownOutEndIsPosedWithinThreePercent) {
  const HardRun r = RunExposed(SharedClip("rgbd_dataset_freiburg1_xyz_first37"),
                               "rgbd_dataset_freiburg1_xyz", Ramps{9, 7, 0.03, 1.45, 1.4, 1.4});
  RecordResult(r);
  // Measured: 22 of 37 posed, worst 2.1% of the matched path (4.8% when the start could take
  // an ambiguous two-view pair, docs/math/two_view.md "Ambiguous pairs").
  ExpectWithinIssue15Bounds(r);
}

// The ramps that judged the hard-exposure handling (docs/reliability.md; nothing was chosen
// on them): 8 dark frames from 5% rising 50% a frame, 6 bright from 1.35x rising 50%.
TEST(HardExposure, TheJudgingRampsArePosedWithinThreePercent) {
  const HardRun r = RunExposed(SharedClip("rgbd_dataset_freiburg1_xyz_first37"),
                               "rgbd_dataset_freiburg1_xyz", Ramps{8, 6, 0.05, 1.5, 1.35, 1.5});
  RecordResult(r);
  // Measured 2026-12-06: 25 of 37 posed, worst 2.76% of the matched path; 3.03% when every
  // buffered frame refined the pair's start (pair_refine_stride 1).
  ExpectWithinIssue15Bounds(r);
}

// The same exposure ramps on the KITTI clip (160 frames, about 90 m driven).
TEST(HardExposure, DrivingClipWithDarkStartAndBlownOutEndIsPosedWithinThreePercent) {
  const HardRun r =
      RunExposed(SharedClip("kitti_odometry_07_first160"), "kitti_odometry_07_first160", Ramps{});
  RecordResult(r);
  ExpectWithinIssue15Bounds(r);
}

}  // namespace
}  // namespace parallax
