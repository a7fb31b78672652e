#include "tools/synth/synthetic_sequence.hpp"

#include <fmt/format.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <opencv2/core.hpp>
#include <vector>

#include "core/check.hpp"
#include "tools/dataset/calibration_yaml.hpp"
#include "tools/dataset/image_file.hpp"
#include "tools/dataset/input_error.hpp"
#include "tools/dataset/opencv_image.hpp"
#include "tools/dataset/trajectory.hpp"
#include "tools/synth/random.hpp"
#include "tools/synth/renderer.hpp"

namespace fs = std::filesystem;

namespace parallax::synth {
namespace {

double Duration(const SynthOptions& o) { return (o.frames - 1) / o.fps; }

// Smooth auto-exposure-like gain, between about 0.64 and 1.57.
float ExposureGain(double t) {
  return static_cast<float>(std::exp(0.25 * std::sin(2.0 * std::numbers::pi * t / 3.0) +
                                     0.2 * std::sin(2.0 * std::numbers::pi * t / 1.3 + 1.0)));
}

float Vignette(int x, int y, int w, int h) {
  const double dx = (x - 0.5 * (w - 1)) / (0.5 * w), dy = (y - 0.5 * (h - 1)) / (0.5 * w);
  const double r2 = (dx * dx + dy * dy) / (1.0 + static_cast<double>(h * h) / (w * w));
  return static_cast<float>(1.0 - 0.3 * r2 - 0.15 * r2 * r2);
}

void WriteLines(const std::string& path, const std::string& text) {
  std::ofstream out(path);
  if (!out) throw InputError(path, "cannot open for writing");
  out << text;
  if (!out) throw InputError(path, "write failed");
}

void WritePng(const std::string& path, const cv::Mat& image) { WritePngFile(path, image, 1); }

}  // namespace

void SynthOptions::Check() const {
  CheckOption(frames >= 2, "SynthOptions", "frames", "must be >= 2");
  CheckOption(width >= 32 && height >= 32, "SynthOptions", "width/height", "must be >= 32");
  CheckOption(std::isfinite(fps) && fps > 0.0, "SynthOptions", "fps", "must be > 0");
  CheckOption(std::isfinite(noise_sigma) && noise_sigma >= 0.0, "SynthOptions", "noise_sigma",
              "must be >= 0");
  CheckOption(std::isfinite(response_gamma) && response_gamma >= 0.2 && response_gamma <= 5.0,
              "SynthOptions", "response_gamma", "must be in [0.2, 5]");
  CheckOption(layout == "tum_rgbd" || layout == "tum_mono", "SynthOptions", "layout",
              "must be tum_rgbd or tum_mono");
  MotionFromString(motion);
}

PinholeCamera SynthCamera(const SynthOptions& o) {
  const double f = 525.0 * o.width / 640.0;
  return PinholeCamera(o.width, o.height, f, f, 0.5 * (o.width - 1), 0.5 * (o.height - 1));
}

double FrameTimestamp(const SynthOptions& o, int index) {
  return std::round(index / o.fps * 1e6) / 1e6;
}

SE3d FramePose(const SynthOptions& o, const Scene& scene, int index) {
  return CameraPose(MotionFromString(o.motion), scene.rig, FrameTimestamp(o, index), Duration(o));
}

SynthFrame RenderSynthFrame(const SynthOptions& o, const Scene& scene, int index) {
  const PinholeCamera camera = SynthCamera(o);
  const Motion motion = MotionFromString(o.motion);
  const double t = FrameTimestamp(o, index);
  RenderedView view = Render(scene, camera, CameraPose(motion, scene.rig, t, Duration(o)));
  if (o.blur) {
    // Average sub-frames over the 40% of the frame interval before t (shutter open).
    constexpr int kSubFrames = 5;
    for (int k = 1; k < kSubFrames; ++k) {
      const double ts = t - 0.4 / o.fps * k / (kSubFrames - 1);
      const RenderedView sub =
          Render(scene, camera, CameraPose(motion, scene.rig, std::max(ts, 0.0), Duration(o)));
      for (std::size_t i = 0; i < view.intensity.NumPixels(); ++i)
        view.intensity.Data()[i] += sub.intensity.Data()[i];
    }
    for (std::size_t i = 0; i < view.intensity.NumPixels(); ++i)
      view.intensity.Data()[i] /= kSubFrames;
  }
  SynthFrame frame{ImageU8(o.width, o.height), std::move(view.depth),
                   o.exposure ? ExposureGain(t) : 1.0f};
  const std::uint64_t noise_seed = o.seed * std::uint64_t{1000003} + static_cast<unsigned>(index);
  Random noise(noise_seed);
  for (int y = 0; y < o.height; ++y) {
    for (int x = 0; x < o.width; ++x) {
      float value = view.intensity(x, y) * frame.gain;
      if (o.vignette) value *= Vignette(x, y, o.width, o.height);
      if (o.noise_sigma > 0.0) value += static_cast<float>(o.noise_sigma * noise.Normal());
      value = std::clamp(value, 0.0f, 255.0f);
      if (o.response_gamma != 1.0) {
        value = 255.0f * std::pow(value / 255.0f, static_cast<float>(1.0 / o.response_gamma));
      }
      frame.image(x, y) = static_cast<std::uint8_t>(std::lround(value));
    }
  }
  return frame;
}

namespace {

/// One frame of the TUM RGB-D layout: rgb/<t>.png, depth/<t>.png (5000 units a metre).
void WriteRgbdFrame(const std::string& out_dir, double t, const SynthFrame& frame,
                    std::string* rgb_list, std::string* depth_list) {
  const std::string stamp = fmt::format("{:.6f}", t);
  WritePng((fs::path(out_dir) / "rgb" / (stamp + ".png")).string(), GreyMatView(frame.image));
  cv::Mat depth(frame.depth.Height(), frame.depth.Width(), CV_16UC1);
  for (int y = 0; y < depth.rows; ++y) {
    for (int x = 0; x < depth.cols; ++x) {
      const double units = std::round(frame.depth(x, y) * 5000.0);
      depth.at<std::uint16_t>(y, x) =
          units > 0.0 && units <= 65535.0 ? static_cast<std::uint16_t>(units) : 0;
    }
  }
  WritePng((fs::path(out_dir) / "depth" / (stamp + ".png")).string(), depth);
  *rgb_list += fmt::format("{} rgb/{}.png\n", stamp, stamp);
  *depth_list += fmt::format("{} depth/{}.png\n", stamp, stamp);
}

/// The TUM monoVO calibration files: camera.txt (pinhole, no rectification), pcalib.txt
/// (G^-1 of the response) and, with a vignette, vignette.png (16-bit).
void WriteMonoCalibration(const SynthOptions& o, const std::string& out_dir) {
  const PinholeCamera K = SynthCamera(o);
  WriteLines((fs::path(out_dir) / "camera.txt").string(),
             fmt::format("Pinhole {} {} {} {} 0\n{} {}\nnone\n{} {}\n", K.Fx(), K.Fy(), K.Cx(),
                         K.Cy(), o.width, o.height, o.width, o.height));
  std::string pcalib;
  for (int i = 0; i < 256; ++i) {
    pcalib +=
        fmt::format("{}{:.6f}", i == 0 ? "" : " ", 255.0 * std::pow(i / 255.0, o.response_gamma));
  }
  WriteLines((fs::path(out_dir) / "pcalib.txt").string(), pcalib + "\n");
  if (!o.vignette) return;
  cv::Mat vignette(o.height, o.width, CV_16UC1);
  for (int y = 0; y < o.height; ++y) {
    for (int x = 0; x < o.width; ++x) {
      vignette.at<std::uint16_t>(y, x) =
          static_cast<std::uint16_t>(std::lround(65535.0f * Vignette(x, y, o.width, o.height)));
    }
  }
  WritePng((fs::path(out_dir) / "vignette.png").string(), vignette);
}

}  // namespace

SynthSummary WriteSyntheticSequence(const SynthOptions& o, const std::string& out_dir) {
  o.Check();
  const Scene scene = MakeScene(o.scene, o.seed, o.textures);
  const bool mono = o.layout == "tum_mono";
  std::error_code ec;
  for (const char* folder :
       mono ? std::vector<const char*>{"images"} : std::vector<const char*>{"rgb", "depth"}) {
    fs::create_directories(fs::path(out_dir) / folder, ec);
  }
  if (ec || !fs::is_directory(fs::path(out_dir) / (mono ? "images" : "rgb"))) {
    throw InputError(out_dir, "cannot create output folders: " + ec.message());
  }
  const std::string header = fmt::format("# parallax synth: scene {} motion {} seed {} frames {}\n",
                                         o.scene, o.motion, o.seed, o.frames);
  std::string rgb_list = header + "# timestamp filename\n";
  std::string depth_list = header + "# timestamp filename (16-bit, 5000 units = 1 m, 0 = none)\n";
  std::string times;  // tum_mono: index, timestamp, exposure (ms; 10 ms at gain 1)
  Trajectory groundtruth;
  SynthSummary summary;
  const auto start = std::chrono::steady_clock::now();
  for (int i = 0; i < o.frames; ++i) {
    const double t = FrameTimestamp(o, i);
    const SynthFrame frame = RenderSynthFrame(o, scene, i);
    if (mono) {
      WritePng((fs::path(out_dir) / "images" / fmt::format("{:05d}.png", i)).string(),
               GreyMatView(frame.image));
      times += fmt::format("{:05d} {:.6f} {:.4f}\n", i, t, 10.0 * frame.gain);
    } else {
      WriteRgbdFrame(out_dir, t, frame, &rgb_list, &depth_list);
    }
    groundtruth.push_back({t, FramePose(o, scene, i)});
    if (i > 0) {
      summary.path_length += (groundtruth[static_cast<std::size_t>(i)].T_w_c.Translation() -
                              groundtruth[static_cast<std::size_t>(i - 1)].T_w_c.Translation())
                                 .norm();
    }
  }
  summary.render_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  summary.frames = o.frames;
  WriteTumTrajectory((fs::path(out_dir) / "groundtruth.txt").string(), groundtruth);
  if (mono) {
    WriteLines((fs::path(out_dir) / "times.txt").string(), times);
    WriteMonoCalibration(o, out_dir);
    return summary;
  }
  WriteLines((fs::path(out_dir) / "rgb.txt").string(), rgb_list);
  WriteLines((fs::path(out_dir) / "depth.txt").string(), depth_list);
  const PinholeCamera K = SynthCamera(o);
  WriteCalibrationYaml(
      (fs::path(out_dir) / "calibration.yaml").string(),
      Camera(CameraModel::kPinhole, K.Width(), K.Height(), K.Fx(), K.Fy(), K.Cx(), K.Cy()), o.fps);
  return summary;
}

}  // namespace parallax::synth
