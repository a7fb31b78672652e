// TUM monoVO layout: images/, times.txt (id timestamp exposure_ms), camera.txt (DSO format),
// pcalib.txt, vignette.png (docs/datasets.md).

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <opencv2/core.hpp>

#include "tools/dataset/calibration_yaml.hpp"
#include "tools/dataset/file_list_reader.hpp"
#include "tools/dataset/image_file.hpp"
#include "tools/dataset/input_error.hpp"
#include "tools/dataset/photometric_corrector.hpp"
#include "tools/dataset/text_lines.hpp"
#include "tools/dataset/trajectory.hpp"

namespace fs = std::filesystem;

namespace parallax {
namespace {

struct MonoCameraFile {
  Camera camera;
  UndistorterOptions rectification;
};

// Relative intrinsics (cx, cy < 1) are fractions of the image size: K00 = w fx,
// K02 = w cx - 0.5 (pixel-centre convention), likewise in y.
std::array<double, 4> ToAbsolute(std::array<double, 4> k, int w, int h) {
  if (k[2] < 1.0 && k[3] < 1.0) {
    k = {k[0] * w, k[1] * h, k[2] * w - 0.5, k[3] * h - 0.5};
  }
  return k;
}

MonoCameraFile ReadMonoCameraFile(const std::string& file) {
  std::ifstream in(file);
  if (!in) throw InputError(file, "cannot open");
  std::string lines[4];
  for (int i = 0; i < 4; ++i) {
    if (!std::getline(in, lines[i])) throw InputError(file, i + 1, "expected 4 lines");
  }
  auto fields = SplitFields(lines[0]);
  std::string model_name = "FOV";
  if (!fields.empty() && std::isalpha(static_cast<unsigned char>(fields[0][0]))) {
    model_name = fields[0];
    fields.erase(fields.begin());
  }
  std::vector<double> values;
  values.reserve(fields.size());
  for (const auto& f : fields) values.push_back(ParseDouble(f, file, 1, "camera parameter"));
  const auto size = ParseNumbers(lines[1], file, 2, 2);
  const int w = ToImageDimension(size[0], file, 2, "image width");
  const int h = ToImageDimension(size[1], file, 2, "image height");
  CameraModel model;
  if (model_name == "FOV") {
    model = CameraModel::kFov;
  } else if (model_name == "RadTan") {
    model = CameraModel::kRadTan;
  } else if (model_name == "EquiDistant") {
    model = CameraModel::kEquidistant;
  } else if (model_name == "Pinhole") {
    model = CameraModel::kPinhole;
  } else {
    throw InputError(file, 1, "unknown camera model '" + model_name + "'");
  }
  if (values.size() < 4) throw InputError(file, 1, "expected fx fy cx cy and distortion");
  std::vector<double> distortion;
  for (std::size_t i = 4; i < values.size(); ++i) distortion.push_back(values[i]);
  if (model == CameraModel::kRadTan && distortion.size() == 4) distortion.push_back(0.0);
  if (model == CameraModel::kPinhole) distortion.clear();
  const auto k = ToAbsolute({values[0], values[1], values[2], values[3]}, w, h);
  const auto make_camera = [&] {
    try {
      return Camera(model, w, h, k[0], k[1], k[2], k[3], distortion);
    } catch (const std::invalid_argument& e) {
      throw InputError(file, 1, e.what());
    }
  };
  MonoCameraFile result{make_camera(), {}};
  const auto out_size = ParseNumbers(lines[3], file, 4, 2);
  result.rectification.output_width = ToImageDimension(out_size[0], file, 4, "output width");
  result.rectification.output_height = ToImageDimension(out_size[1], file, 4, "output height");
  const auto mode = SplitFields(lines[2]);
  if (mode.size() == 1 && mode[0] == "crop") {
    result.rectification.mode = UndistortMode::kCrop;
  } else if (mode.size() == 1 && (mode[0] == "full" || mode[0] == "none")) {
    result.rectification.mode = UndistortMode::kFull;
  } else {
    const auto v = ParseNumbers(lines[2], file, 3, 4, /*allow_more=*/true);
    const auto ko = ToAbsolute({v[0], v[1], v[2], v[3]}, result.rectification.output_width,
                               result.rectification.output_height);
    result.rectification.mode = UndistortMode::kExplicit;
    result.rectification.fx = ko[0];
    result.rectification.fy = ko[1];
    result.rectification.cx = ko[2];
    result.rectification.cy = ko[3];
  }
  return result;
}

PhotometricCalibration ReadPhotometric(const fs::path& folder, const Camera& camera) {
  PhotometricCalibration photometric;
  const std::string pcalib = (folder / "pcalib.txt").string();
  if (fs::exists(pcalib)) {
    ForEachDataLine(pcalib, [&](const std::string& line, int line_number) {
      for (const double v : ParseNumbers(line, pcalib, line_number, 256)) {
        photometric.inverse_response.push_back(static_cast<float>(v));
      }
    });
  }
  const std::string vignette = (folder / "vignette.png").string();
  if (fs::exists(vignette)) {
    const cv::Mat v = ReadImageFile(vignette, ImageReadMode::kUnchanged);
    if (v.channels() != 1) throw InputError(vignette, "not a grey image");
    if (v.cols != camera.Width() || v.rows != camera.Height()) {
      throw InputError(vignette, "size differs from the camera");
    }
    cv::Mat as_float;
    double max_value = 0.0;
    v.convertTo(as_float, CV_32F);
    cv::minMaxLoc(as_float, nullptr, &max_value);
    ImageF image(v.cols, v.rows);
    for (int y = 0; y < v.rows; ++y) {
      for (int x = 0; x < v.cols; ++x) {
        image(x, y) = as_float.at<float>(y, x) / static_cast<float>(max_value);
      }
    }
    photometric.vignette = std::move(image);
  }
  // The corrector's checks, each with its file named.
  const auto check = [&](const PhotometricCalibration& part, const std::string& file) {
    try {
      const PhotometricCorrector corrector(part, camera.Width(), camera.Height());
    } catch (const std::invalid_argument& e) {
      throw InputError(file, e.what());
    }
  };
  check(PhotometricCalibration{photometric.inverse_response, std::nullopt}, pcalib);
  check(PhotometricCalibration{{}, photometric.vignette}, vignette);
  return photometric;
}

}  // namespace

std::unique_ptr<DatasetReader> OpenTumMono(const std::string& path,
                                           const std::string& calibration) {
  const fs::path folder(path);
  const fs::path images = folder / "images";
  if (!fs::is_directory(images)) {
    throw InputError(path, fs::exists(folder / "images.zip")
                               ? "images.zip is not read directly; unzip it into images/"
                               : "no images/ folder");
  }
  FileListSpec spec;
  spec.format = DatasetFormat::kTumMono;
  if (calibration.empty()) {
    MonoCameraFile camera_file = ReadMonoCameraFile((folder / "camera.txt").string());
    spec.camera = camera_file.camera;
    spec.rectification = camera_file.rectification;
  } else {
    spec.camera = ReadCalibrationYaml(calibration).camera;
  }
  std::vector<std::string> files;
  for (const auto& entry : fs::directory_iterator(images)) files.push_back(entry.path().string());
  std::sort(files.begin(), files.end());
  const std::string times = (folder / "times.txt").string();
  ForEachDataLine(times, [&](const std::string& line, int line_number) {
    const auto v = ParseNumbers(line, times, line_number, 2, /*allow_more=*/true);
    ImageEntry entry;
    entry.timestamp = v[1];
    const auto fields = SplitFields(line);
    if (fields.size() >= 3)
      entry.exposure_ms = ParseDouble(fields[2], times, line_number, "exposure");
    if (spec.entries.size() >= files.size()) {
      throw InputError(times, line_number, "more lines than images in images/");
    }
    entry.path = files[spec.entries.size()];
    entry.list_file = times;
    entry.list_line = line_number;
    spec.entries.push_back(std::move(entry));
  });
  if (spec.entries.size() != files.size()) {
    throw InputError(times, "has " + std::to_string(spec.entries.size()) +
                                " lines but images/ has " + std::to_string(files.size()) +
                                " files");
  }
  spec.photometric = ReadPhotometric(folder, *spec.camera);
  // Not part of the TUM monoVO layout (it gives start and end segments only); rendered
  // sequences in this layout write one (parallax synth --layout tum_mono).
  const std::string gt = (folder / "groundtruth.txt").string();
  if (fs::exists(gt)) spec.groundtruth = [gt] { return ReadTumTrajectory(gt); };
  return std::make_unique<FileListReader>(std::move(spec));
}

}  // namespace parallax
