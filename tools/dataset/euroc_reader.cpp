// EuRoC ASL layout: mav0/cam0/{data.csv, data/*.png, sensor.yaml} and
// mav0/state_groundtruth_estimate0/data.csv (docs/datasets.md).

#include <yaml-cpp/yaml.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "tools/dataset/calibration_yaml.hpp"
#include "tools/dataset/file_list_reader.hpp"
#include "tools/dataset/groundtruth_files.hpp"
#include "tools/dataset/input_error.hpp"
#include "tools/dataset/text_lines.hpp"

namespace fs = std::filesystem;

namespace parallax {
namespace {

fs::path Mav0(const fs::path& path) {
  if (fs::is_directory(path / "mav0")) return path / "mav0";
  return path;
}

// EuRoC's sensor.yaml starts with an OpenCV "%YAML:1.0" directive that yaml-cpp rejects.
YAML::Node LoadSensorYaml(const std::string& file) {
  std::ifstream in(file);
  if (!in) throw InputError(file, "cannot open");
  std::stringstream text;
  std::string line;
  bool first = true;
  while (std::getline(in, line)) {
    if (first && line.rfind("%YAML", 0) == 0) line.insert(0, "#");
    first = false;
    text << line << "\n";
  }
  try {
    return YAML::Load(text.str());
  } catch (const YAML::ParserException& e) {
    throw InputError(file, e.mark.line + 1, "YAML syntax error: " + e.msg);
  }
}

struct EurocCamera {
  Camera camera;
  SE3d T_B_S;  // sensor (camera) to body (IMU)
};

EurocCamera ReadSensorYaml(const std::string& file) {
  const YAML::Node root = LoadSensorYaml(file);
  try {
    const auto T = root["T_BS"]["data"].as<std::vector<double>>();
    const auto resolution = root["resolution"].as<std::vector<int>>();
    const auto k = root["intrinsics"].as<std::vector<double>>();
    auto d = root["distortion_coefficients"].as<std::vector<double>>();
    const std::string model_name = root["distortion_model"].as<std::string>();
    if (T.size() != 16 || resolution.size() != 2 || k.size() != 4) {
      throw InputError(file, "T_BS.data needs 16 values, resolution 2, intrinsics 4");
    }
    const CameraModel model = CameraModelFromString(model_name);
    if (model == CameraModel::kRadTan && d.size() == 4) d.push_back(0.0);  // k3 = 0
    Eigen::Matrix4d M;
    for (int i = 0; i < 16; ++i) M(i / 4, i % 4) = T[static_cast<std::size_t>(i)];
    return {Camera(model, resolution[0], resolution[1], k[0], k[1], k[2], k[3], d), SE3d(M)};
  } catch (const YAML::Exception& e) {
    throw InputError(file, e.mark.line + 1, std::string("malformed sensor.yaml: ") + e.what());
  } catch (const std::invalid_argument& e) {
    throw InputError(file, e.what());
  }
}

Trajectory ReadEurocGroundTruth(const std::string& file, const SE3d& T_B_S) {
  Trajectory trajectory;
  ForEachDataLine(file, [&](const std::string& line, int line_number) {
    const auto v = ParseNumbers(line, file, line_number, 8, /*allow_more=*/true);
    const Eigen::Quaterniond q_W_B(v[4], v[5], v[6], v[7]);  // w x y z
    if (q_W_B.norm() < 1e-6) throw InputError(file, line_number, "zero quaternion");
    const SE3d T_W_B(SO3d(q_W_B), Eigen::Vector3d(v[1], v[2], v[3]));
    const double t = v[0] * 1e-9;
    if (!trajectory.empty() && !(t > trajectory.back().timestamp)) {
      throw InputError(file, line_number, "timestamps must increase");
    }
    trajectory.push_back({t, T_W_B * T_B_S});
  });
  return trajectory;
}

}  // namespace

Trajectory ReadEurocGroundTruthFile(const std::string& data_csv, const std::string& sensor_yaml) {
  return ReadEurocGroundTruth(data_csv, ReadSensorYaml(sensor_yaml).T_B_S);
}

std::unique_ptr<DatasetReader> OpenEuroc(const std::string& path, const std::string& calibration) {
  const fs::path mav0 = Mav0(path);
  const fs::path cam0 = mav0 / "cam0";
  const std::string list = (cam0 / "data.csv").string();
  EurocCamera sensor = calibration.empty()
                           ? ReadSensorYaml((cam0 / "sensor.yaml").string())
                           : EurocCamera{ReadCalibrationYaml(calibration).camera, SE3d()};
  FileListSpec spec;
  spec.format = DatasetFormat::kEuroc;
  spec.camera = sensor.camera;
  ForEachDataLine(list, [&](const std::string& line, int line_number) {
    const auto fields = SplitFields(line);
    if (fields.size() != 2) throw InputError(list, line_number, "expected 'timestamp_ns,filename'");
    ImageEntry entry;
    entry.timestamp = ParseDouble(fields[0], list, line_number, "timestamp") * 1e-9;
    entry.path = (cam0 / "data" / fields[1]).string();
    entry.list_file = list;
    entry.list_line = line_number;
    spec.entries.push_back(std::move(entry));
  });
  if (spec.entries.empty()) throw InputError(list, "lists no images");
  const fs::path gt = mav0 / "state_groundtruth_estimate0" / "data.csv";
  if (fs::exists(gt)) {
    spec.groundtruth = [file = gt.string(), T = sensor.T_B_S] {
      return ReadEurocGroundTruth(file, T);
    };
  }
  return std::make_unique<FileListReader>(std::move(spec));
}

}  // namespace parallax
