// KITTI odometry layout: <root>/sequences/XX/{image_0/*.png, times.txt, calib.txt} and
// <root>/poses/XX.txt (docs/datasets.md).

#include <filesystem>
#include <fstream>

#include "tools/dataset/calibration_yaml.hpp"
#include "tools/dataset/file_list_reader.hpp"
#include "tools/dataset/input_error.hpp"
#include "tools/dataset/text_lines.hpp"

namespace fs = std::filesystem;

namespace parallax {
namespace {

// The sequence folder: `path` itself if it holds image_0/, else the only folder in
// path/sequences/.
fs::path SequenceFolder(const fs::path& path) {
  if (fs::is_directory(path / "image_0")) return path;
  const fs::path sequences = path / "sequences";
  if (!fs::is_directory(sequences)) throw InputError(path.string(), "no image_0/ or sequences/");
  std::vector<fs::path> found;
  for (const auto& entry : fs::directory_iterator(sequences)) {
    if (fs::is_directory(entry.path() / "image_0")) found.push_back(entry.path());
  }
  if (found.size() != 1) {
    throw InputError(sequences.string(),
                     "expected exactly one sequence folder with image_0/, found " +
                         std::to_string(found.size()) + "; pass the sequence folder itself");
  }
  return found.front();
}

// K from the P0 line of calib.txt (no distortion: KITTI images are rectified).
Camera ReadKittiCamera(const std::string& calib, int width, int height) {
  std::optional<Camera> camera;
  ForEachDataLine(calib, [&](const std::string& line, int line_number) {
    if (line.rfind("P0:", 0) != 0) return;
    const auto v = ParseNumbers(line.substr(3), calib, line_number, 12);
    try {
      camera = Camera(CameraModel::kPinhole, width, height, v[0], v[5], v[2], v[6]);
    } catch (const std::invalid_argument& e) {
      throw InputError(calib, line_number, e.what());
    }
  });
  if (!camera) throw InputError(calib, "no 'P0:' line");
  return *camera;
}

}  // namespace

std::unique_ptr<DatasetReader> OpenKitti(const std::string& path, const std::string& calibration) {
  const fs::path sequence = SequenceFolder(path);
  const std::string times = (sequence / "times.txt").string();
  FileListSpec spec;
  spec.format = DatasetFormat::kKitti;
  ForEachDataLine(times, [&](const std::string& line, int line_number) {
    ImageEntry entry;
    entry.timestamp = ParseNumbers(line, times, line_number, 1)[0];
    char name[32];
    std::snprintf(name, sizeof(name), "%06zu.png", spec.entries.size());
    entry.path = (sequence / "image_0" / name).string();
    entry.list_file = times;
    entry.list_line = line_number;
    spec.entries.push_back(std::move(entry));
  });
  if (spec.entries.empty()) throw InputError(times, "lists no frames");
  if (!calibration.empty()) {
    spec.camera = ReadCalibrationYaml(calibration).camera;
  } else {
    // calib.txt has no image size: take it from the first image.
    const auto [width, height] = ProbeImageSize(spec.entries.front().path);
    spec.camera = ReadKittiCamera((sequence / "calib.txt").string(), width, height);
  }
  const fs::path poses =
      sequence.parent_path().parent_path() / "poses" / (sequence.filename().string() + ".txt");
  if (fs::exists(poses)) {
    std::vector<double> stamps;
    for (const ImageEntry& e : spec.entries) stamps.push_back(e.timestamp);
    spec.groundtruth = [file = poses.string(), stamps] {
      return ReadKittiTrajectory(file, stamps);
    };
  }
  return std::make_unique<FileListReader>(std::move(spec));
}

}  // namespace parallax
