#include "tools/dataset/calibration_yaml.hpp"

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <fstream>

#include "tools/dataset/input_error.hpp"

namespace parallax {
namespace {

int LineOf(const YAML::Node& node) { return node.Mark().line >= 0 ? node.Mark().line + 1 : 0; }

YAML::Node Require(const YAML::Node& root, const std::string& key, const std::string& path) {
  const YAML::Node node = root[key];
  if (!node) throw InputError(path, LineOf(root), "missing key '" + key + "'");
  return node;
}

double ReadNumber(const YAML::Node& node, const std::string& key, const std::string& path) {
  try {
    const double value = node.as<double>();
    if (!std::isfinite(value)) throw InputError(path, LineOf(node), key + " is not finite");
    return value;
  } catch (const YAML::Exception&) {
    throw InputError(path, LineOf(node), key + " must be a number");
  }
}

int ReadInt(const YAML::Node& node, const std::string& key, const std::string& path) {
  try {
    return node.as<int>();
  } catch (const YAML::Exception&) {
    throw InputError(path, LineOf(node), key + " must be an integer");
  }
}

}  // namespace

CalibrationFile ReadCalibrationYaml(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path, "cannot open calibration file");
  YAML::Node root;
  try {
    root = YAML::Load(in);
  } catch (const YAML::ParserException& e) {
    throw InputError(path, e.mark.line + 1, "YAML syntax error: " + e.msg);
  }
  if (!root.IsMap()) throw InputError(path, "calibration must be a YAML mapping");
  const YAML::Node model_node = Require(root, "model", path);
  CameraModel model;
  try {
    model = CameraModelFromString(model_node.as<std::string>());
  } catch (const std::exception& e) {
    throw InputError(path, LineOf(model_node), e.what());
  }
  const int width = ReadInt(Require(root, "width", path), "width", path);
  const int height = ReadInt(Require(root, "height", path), "height", path);
  const double fx = ReadNumber(Require(root, "fx", path), "fx", path);
  const double fy = ReadNumber(Require(root, "fy", path), "fy", path);
  const double cx = ReadNumber(Require(root, "cx", path), "cx", path);
  const double cy = ReadNumber(Require(root, "cy", path), "cy", path);
  std::vector<double> distortion;
  if (const YAML::Node d = root["distortion"]) {
    if (!d.IsSequence()) throw InputError(path, LineOf(d), "distortion must be a list");
    for (const YAML::Node& value : d) distortion.push_back(ReadNumber(value, "distortion", path));
  }
  std::optional<double> fps;
  if (const YAML::Node f = root["fps"]) {
    fps = ReadNumber(f, "fps", path);
    if (!(*fps > 0.0)) throw InputError(path, LineOf(f), "fps must be > 0");
  }
  try {
    return CalibrationFile{Camera(model, width, height, fx, fy, cx, cy, distortion), fps};
  } catch (const std::invalid_argument& e) {
    throw InputError(path, LineOf(root), e.what());
  }
}

void WriteCalibrationYaml(const std::string& path, const Camera& camera,
                          std::optional<double> fps) {
  std::ofstream out(path);
  if (!out) throw InputError(path, "cannot open for writing");
  const PinholeCamera& K = camera.Intrinsics();
  out << "# Parallax camera calibration (docs/calibration.md); intrinsics in pixels,\n"
      << "# pixel (0,0) = centre of the top-left pixel.\n";
  out << "model: " << ToString(camera.Model()) << "\n";
  out << "width: " << K.Width() << "\nheight: " << K.Height() << "\n";
  out << fmt::format("fx: {}\nfy: {}\ncx: {}\ncy: {}\n", K.Fx(), K.Fy(), K.Cx(), K.Cy());
  if (!camera.Distortion().empty()) {
    out << "distortion: [" << fmt::format("{}", fmt::join(camera.Distortion(), ", ")) << "]\n";
  }
  if (fps) out << fmt::format("fps: {}\n", *fps);
  if (!out) throw InputError(path, "write failed");
}

}  // namespace parallax
