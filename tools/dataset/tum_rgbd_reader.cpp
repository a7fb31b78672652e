// TUM RGB-D layout: rgb.txt, rgb/*.png, groundtruth.txt; intrinsics from a calibration file
// or from freiburg1/2/3 in the folder name (docs/datasets.md).

#include <filesystem>

#include "tools/dataset/calibration_yaml.hpp"
#include "tools/dataset/file_list_reader.hpp"
#include "tools/dataset/input_error.hpp"
#include "tools/dataset/text_lines.hpp"

namespace parallax {
namespace {

// Published calibrations of the TUM RGB-D colour cameras (radtan, OpenCV order).
std::optional<Camera> FreiburgCamera(const std::string& folder) {
  const std::string name = std::filesystem::absolute(folder).lexically_normal().string();
  if (name.find("freiburg1") != std::string::npos) {
    return Camera(CameraModel::kRadTan, 640, 480, 517.306408, 516.469215, 318.643040, 255.313989,
                  {0.262383, -0.953104, -0.005358, 0.002628, 1.163314});
  }
  if (name.find("freiburg2") != std::string::npos) {
    return Camera(CameraModel::kRadTan, 640, 480, 520.908620, 521.007327, 325.141442, 249.701764,
                  {0.231222, -0.784899, -0.003257, -0.000105, 0.917205});
  }
  if (name.find("freiburg3") != std::string::npos) {
    return Camera(CameraModel::kPinhole, 640, 480, 535.4, 539.2, 320.1, 247.6);
  }
  return std::nullopt;
}

}  // namespace

std::unique_ptr<DatasetReader> OpenTumRgbd(const std::string& path,
                                           const std::string& calibration) {
  const std::filesystem::path folder(path);
  const std::string list = (folder / "rgb.txt").string();
  FileListSpec spec;
  spec.format = DatasetFormat::kTumRgbd;
  const std::string calib_file = FindCalibrationFile(path, calibration);
  if (!calib_file.empty()) {
    spec.camera = ReadCalibrationYaml(calib_file).camera;
  } else if (auto camera = FreiburgCamera(path)) {
    spec.camera = *camera;
  } else {
    throw InputError(path,
                     "cannot tell the camera: the folder name has no freiburg1/2/3 and "
                     "there is no calibration.yaml; pass --calib FILE");
  }
  ForEachDataLine(list, [&](const std::string& line, int line_number) {
    const auto fields = SplitFields(line);
    if (fields.size() != 2) throw InputError(list, line_number, "expected 'timestamp filename'");
    ImageEntry entry;
    entry.timestamp = ParseDouble(fields[0], list, line_number, "timestamp");
    entry.path = (folder / fields[1]).string();
    entry.list_file = list;
    entry.list_line = line_number;
    spec.entries.push_back(std::move(entry));
  });
  if (spec.entries.empty()) throw InputError(list, "lists no images");
  const std::string gt = (folder / "groundtruth.txt").string();
  if (std::filesystem::exists(gt)) spec.groundtruth = [gt] { return ReadTumTrajectory(gt); };
  return std::make_unique<FileListReader>(std::move(spec));
}

}  // namespace parallax
