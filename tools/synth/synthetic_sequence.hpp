#pragma once
// Writing a rendered sequence in the TUM RGB-D or monoVO layout (docs/synthetic.md).

#include <cstdint>
#include <string>
#include <vector>

#include "core/image.hpp"
#include "core/pinhole_camera.hpp"
#include "core/se3.hpp"
#include "tools/synth/motion.hpp"
#include "tools/synth/scene.hpp"

namespace parallax::synth {

struct SynthOptions {
  std::string scene = "room";
  std::string motion = "shake";
  int frames = 60;
  std::uint64_t seed = 1;
  int width = 640;
  int height = 480;
  double fps = 30.0;
  bool exposure = false;              ///< auto-exposure-like gain changes (up to about x1.6)
  double noise_sigma = 0.0;           ///< Gaussian sensor noise, grey levels
  bool vignette = false;              ///< radial fall-off to ~55% in the corners
  bool blur = false;                  ///< motion blur: 5 sub-frames over 40% of the frame interval
  std::vector<std::string> textures;  ///< image files replacing procedural textures
  /// Camera response: stored grey = 255 (E / 255)^(1 / gamma) of the exposed irradiance E
  /// (1: linear). tum_mono writes its inverse to pcalib.txt.
  double response_gamma = 1.0;
  /// "tum_rgbd" (rgb/, depth/, rgb.txt, calibration.yaml) or "tum_mono" (images/, times.txt
  /// with exposure times, camera.txt, pcalib.txt, vignette.png with --vignette), both with
  /// groundtruth.txt.
  std::string layout = "tum_rgbd";

  /// Throws std::invalid_argument naming the bad field.
  void Check() const;
};

/// The synthetic camera: fx = fy = 525 * width / 640, principal point at the image centre.
PinholeCamera SynthCamera(const SynthOptions& options);

/// Timestamp of frame i: i / fps rounded to microseconds (as TUM files print them).
double FrameTimestamp(const SynthOptions& options, int index);

/// Ground-truth camera-to-world pose of frame i.
SE3d FramePose(const SynthOptions& options, const Scene& scene, int index);

/// One finished frame: 8-bit image after photometric effects, and true depth (metres).
struct SynthFrame {
  ImageU8 image;
  ImageF depth;
  float gain = 1.0f;  ///< exposure gain applied
};
SynthFrame RenderSynthFrame(const SynthOptions& options, const Scene& scene, int index);

struct SynthSummary {
  int frames = 0;
  double path_length = 0.0;  ///< metres
  double render_seconds = 0.0;
};

/// Renders and writes out_dir in `options.layout`: tum_rgbd {rgb/, depth/, rgb.txt,
/// depth.txt, groundtruth.txt, calibration.yaml} or tum_mono {images/, times.txt,
/// camera.txt, pcalib.txt, vignette.png, groundtruth.txt}. Throws InputError if out_dir
/// cannot be written.
SynthSummary WriteSyntheticSequence(const SynthOptions& options, const std::string& out_dir);

}  // namespace parallax::synth
