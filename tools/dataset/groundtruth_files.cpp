#include "tools/dataset/groundtruth_files.hpp"

#include <filesystem>

#include "tools/dataset/dataset_reader.hpp"
#include "tools/dataset/input_error.hpp"
#include "tools/dataset/text_lines.hpp"

namespace fs = std::filesystem;

namespace parallax {
namespace {

std::vector<double> ReadTimes(const std::string& path) {
  std::vector<double> times;
  ForEachDataLine(path, [&](const std::string& line, int number) {
    times.push_back(ParseNumbers(line, path, number, 1)[0]);
  });
  return times;
}

std::string FindKittiTimes(const std::string& poses, const std::string& given,
                           const std::string& fallback) {
  if (!given.empty()) return given;
  const fs::path p(poses);
  const fs::path sibling = p.parent_path() / (p.stem().string() + ".times.txt");
  if (fs::exists(sibling)) return sibling.string();
  const fs::path layout = p.parent_path().parent_path() / "sequences" / p.stem() / "times.txt";
  if (fs::exists(layout)) return layout.string();
  if (!fallback.empty()) return fallback;
  throw InputError(poses, "KITTI poses need timestamps: give --times (times.txt), or put " +
                              sibling.filename().string() + " beside the file");
}

std::string FindEurocSensor(const std::string& csv, const std::string& given) {
  if (!given.empty()) return given;
  const fs::path sensor = fs::path(csv).parent_path().parent_path() / "cam0" / "sensor.yaml";
  if (fs::exists(sensor)) return sensor.string();
  throw InputError(csv,
                   "EuRoC ground truth needs the camera extrinsics: give --sensor "
                   "(cam0/sensor.yaml)");
}

}  // namespace

TrajectoryFileFormat DetectTrajectoryFormat(const std::string& path) {
  std::size_t fields = 0;
  int first_line = 0;
  ForEachDataLine(path, [&](const std::string& line, int number) {
    if (first_line == 0) {
      fields = SplitFields(line).size();
      first_line = number;
    }
  });
  if (first_line == 0) throw InputError(path, "has no poses");
  if (fs::path(path).extension() == ".csv" && fields >= 8) return TrajectoryFileFormat::kEuroc;
  if (fields == 12) return TrajectoryFileFormat::kKitti;
  if (fields == 8) return TrajectoryFileFormat::kTum;
  throw InputError(path, first_line,
                   "not a trajectory: " + std::to_string(fields) +
                       " fields (TUM has 8, KITTI 12, EuRoC data.csv at least 8 comma-separated)");
}

Trajectory ReadTrajectoryFile(const TrajectorySource& source) {
  switch (DetectTrajectoryFormat(source.path)) {
    case TrajectoryFileFormat::kEuroc:
      return ReadEurocGroundTruthFile(source.path, FindEurocSensor(source.path, source.sensor));
    case TrajectoryFileFormat::kKitti: {
      const std::string times = FindKittiTimes(source.path, source.times, source.fallback_times);
      return ReadKittiTrajectory(source.path, ReadTimes(times));
    }
    case TrajectoryFileFormat::kTum:
      break;
  }
  return ReadTumTrajectory(source.path);
}

DatasetGroundTruth ReadDatasetGroundTruth(const std::string& folder) {
  const auto reader = OpenDataset(folder);
  auto poses = reader->GroundTruth();
  if (!poses) throw InputError(folder, "the dataset has no ground truth");
  return {std::move(*poses), reader->FrameTimestamps()};
}

}  // namespace parallax
