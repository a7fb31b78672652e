#pragma once
// Trajectory files in the formats the benchmarks ship, read directly (no conversion step):
// TUM, KITTI poses (with times.txt) and EuRoC ground truth (with the camera's extrinsics).

#include <string>
#include <vector>

#include "tools/dataset/trajectory.hpp"

namespace parallax {

/// EuRoC state_groundtruth_estimate0/data.csv (body poses, ns timestamps) turned into
/// camera-to-world poses of cam0 with T_BS from its sensor.yaml: T_w_c = T_w_b * T_b_s.
Trajectory ReadEurocGroundTruthFile(const std::string& data_csv, const std::string& sensor_yaml);

enum class TrajectoryFileFormat { kTum, kKitti, kEuroc };

/// A trajectory file and what it takes to read it. `times`: KITTI timestamps (times.txt);
/// `sensor`: EuRoC sensor.yaml. Empty fields are found next to the file where the benchmark
/// layout puts them (KITTI poses/XX.txt -> sequences/XX/times.txt, or a sibling
/// <name>.times.txt; EuRoC mav0/state_groundtruth_estimate0/data.csv -> mav0/cam0/sensor.yaml).
struct TrajectorySource {
  std::string path;
  std::string times;
  std::string sensor;
  /// KITTI timestamps used when `times` is empty and none are found beside the file (an
  /// estimate with one pose per image takes the ground truth's, as KITTI's devkit does).
  std::string fallback_times = {};
};

/// The format by content: EuRoC for a .csv whose lines have >= 8 numbers, KITTI for 12
/// numbers per line, TUM for 8. Throws InputError naming the file otherwise.
TrajectoryFileFormat DetectTrajectoryFormat(const std::string& path);

/// Reads any of the three formats (camera-to-world). Throws InputError naming the file (and
/// line) for a malformed file, a missing times/sensor file, or a count mismatch.
Trajectory ReadTrajectoryFile(const TrajectorySource& source);

/// Ground truth of a dataset folder (any layout the readers know) and its image timestamps.
struct DatasetGroundTruth {
  Trajectory poses;
  std::vector<double> frame_timestamps;
};
/// Throws InputError when the dataset has no ground truth.
DatasetGroundTruth ReadDatasetGroundTruth(const std::string& folder);

}  // namespace parallax
