#include "tools/dataset/dataset_reader.hpp"

#include <filesystem>

#include "core/calibration_check.hpp"
#include "tools/dataset/file_list_reader.hpp"
#include "tools/dataset/input_error.hpp"

namespace fs = std::filesystem;

namespace parallax {

std::string ToString(DatasetFormat format) {
  switch (format) {
    case DatasetFormat::kAuto:
      return "auto";
    case DatasetFormat::kTumRgbd:
      return "tum";
    case DatasetFormat::kTumMono:
      return "monovo";
    case DatasetFormat::kEuroc:
      return "euroc";
    case DatasetFormat::kKitti:
      return "kitti";
    case DatasetFormat::kImages:
      return "images";
    case DatasetFormat::kVideo:
      return "video";
  }
  return "auto";
}

DatasetFormat DatasetFormatFromString(const std::string& name) {
  for (const auto format : {DatasetFormat::kAuto, DatasetFormat::kTumRgbd, DatasetFormat::kTumMono,
                            DatasetFormat::kEuroc, DatasetFormat::kKitti, DatasetFormat::kImages,
                            DatasetFormat::kVideo}) {
    if (ToString(format) == name) return format;
  }
  throw std::invalid_argument("unknown dataset format '" + name +
                              "' (expected auto, tum, monovo, euroc, kitti, images or video)");
}

DatasetFormat DetectDatasetFormat(const std::string& path) {
  const fs::path p(path);
  if (!fs::exists(p)) throw InputError(path, "does not exist");
  if (fs::is_regular_file(p)) return DatasetFormat::kVideo;
  if (fs::exists(p / "rgb.txt")) return DatasetFormat::kTumRgbd;
  if (fs::exists(p / "mav0" / "cam0" / "data.csv") || fs::exists(p / "cam0" / "data.csv")) {
    return DatasetFormat::kEuroc;
  }
  if (fs::is_directory(p / "sequences") ||
      (fs::is_directory(p / "image_0") && fs::exists(p / "times.txt"))) {
    return DatasetFormat::kKitti;
  }
  if (fs::exists(p / "camera.txt") && fs::exists(p / "times.txt") &&
      (fs::is_directory(p / "images") || fs::exists(p / "images.zip"))) {
    return DatasetFormat::kTumMono;
  }
  const fs::path images = fs::is_directory(p / "images") ? p / "images" : p;
  for (const auto& entry : fs::directory_iterator(images)) {
    if (entry.is_regular_file() && IsImageFile(entry.path())) return DatasetFormat::kImages;
  }
  throw InputError(path,
                   "cannot recognise the dataset layout (looked for TUM rgb.txt, EuRoC "
                   "mav0/cam0/data.csv, KITTI sequences/ or image_0/, monoVO camera.txt + "
                   "times.txt, or image files); use --format");
}

namespace {

std::unique_ptr<DatasetReader> OpenLayout(const std::string& path, const DatasetOptions& options) {
  const DatasetFormat format =
      options.format == DatasetFormat::kAuto ? DetectDatasetFormat(path) : options.format;
  if (format != DatasetFormat::kVideo && !fs::is_directory(path)) {
    throw InputError(path, "is not a folder");
  }
  switch (format) {
    case DatasetFormat::kTumRgbd:
      return OpenTumRgbd(path, options.calibration_file);
    case DatasetFormat::kTumMono:
      return OpenTumMono(path, options.calibration_file);
    case DatasetFormat::kEuroc:
      return OpenEuroc(path, options.calibration_file);
    case DatasetFormat::kKitti:
      return OpenKitti(path, options.calibration_file);
    case DatasetFormat::kImages:
      return OpenImageFolder(path, options.calibration_file);
    case DatasetFormat::kVideo:
      return OpenVideo(path, options.calibration_file);
    case DatasetFormat::kAuto:
      break;
  }
  throw InputError(path, "unsupported format");
}

}  // namespace

std::unique_ptr<DatasetReader> OpenDataset(const std::string& path, const DatasetOptions& options) {
  auto reader = OpenLayout(path, options);
  // A calibration that no lens can have is a typo or the wrong file, and tracking with it
  // would still report "tracked" (docs/calibration.md, "Plausibility").
  const std::string problem = CalibrationProblem(reader->GetCamera());
  if (!problem.empty()) {
    std::string source =
        FindCalibrationFile(fs::is_directory(path) ? path : ".", options.calibration_file);
    if (source.empty()) source = path;  // the layout's own calibration (calib.txt, ...)
    throw InputError(source, "implausible calibration: " + problem);
  }
  return reader;
}

}  // namespace parallax
