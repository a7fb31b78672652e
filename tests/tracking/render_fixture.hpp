#pragma once
// Rendered keyframes and frames with exact poses and depth for tracker tests.

#include <cmath>
#include <memory>

#include "core/frame.hpp"
#include "tools/synth/random.hpp"
#include "tools/synth/renderer.hpp"
#include "tools/synth/synthetic_sequence.hpp"

namespace parallax::test {

struct RenderedKeyframe {
  std::shared_ptr<const Frame> frame;
  ImageF idepth;
  ImageF variance;
  SE3d T_w_c;
  double mean_depth = 0.0;
};

inline PinholeCamera TestCamera() { return PinholeCamera(640, 480, 525.0, 525.0, 319.5, 239.5); }

/// The scene seen from T_w_c by TestCamera() (= synth::SynthCamera({})) as 8 bits: intensity
/// times `gain`, plus Gaussian noise, rounded and clipped.
inline ImageU8 RenderTestImage(const synth::Scene& scene, const SE3d& T_w_c, float gain = 1.0f,
                               double noise_sigma = 0.0, std::uint64_t seed = 1) {
  const PinholeCamera K = TestCamera();
  const synth::RenderedView view = synth::Render(scene, K, T_w_c);
  synth::Random rng(seed);
  ImageU8 image(K.Width(), K.Height());
  for (std::size_t i = 0; i < image.NumPixels(); ++i) {
    double v = gain * view.intensity.Data()[i];
    if (noise_sigma > 0.0) v += noise_sigma * rng.Normal();
    image.Data()[i] = static_cast<std::uint8_t>(std::lround(std::clamp(v, 0.0, 255.0)));
  }
  return image;
}

/// Renders the scene at T_w_c with brightness gain and Gaussian noise.
inline std::shared_ptr<const Frame> RenderTestFrame(const synth::Scene& scene, const SE3d& T_w_c,
                                                    std::int64_t id, float gain = 1.0f,
                                                    double noise_sigma = 0.0,
                                                    std::uint64_t seed = 1) {
  return std::make_shared<const Frame>(id, 0.0, TestCamera(),
                                       RenderTestImage(scene, T_w_c, gain, noise_sigma, seed));
}

/// A keyframe with ground-truth inverse depth (relative sigma 1%), excluding pixels at depth
/// discontinuities where rendered intensities mix two surfaces.
inline RenderedKeyframe RenderTestKeyframe(const synth::Scene& scene, const SE3d& T_w_c,
                                           float gain = 1.0f, double noise_sigma = 0.0) {
  const PinholeCamera K = TestCamera();
  const synth::RenderedView view = synth::Render(scene, K, T_w_c);
  RenderedKeyframe kf;
  kf.frame = RenderTestFrame(scene, T_w_c, 0, gain, noise_sigma, 99);
  kf.T_w_c = T_w_c;
  kf.idepth = ImageF(K.Width(), K.Height(), 0.0f);
  kf.variance = ImageF(K.Width(), K.Height(), 0.0f);
  double sum = 0.0;
  int count = 0;
  for (int y = 1; y < K.Height() - 1; ++y) {
    for (int x = 1; x < K.Width() - 1; ++x) {
      float lo = 1e9f, hi = 0.0f;
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          lo = std::min(lo, view.depth(x + dx, y + dy));
          hi = std::max(hi, view.depth(x + dx, y + dy));
        }
      }
      if (lo <= 0.0f || hi > 1.01f * lo) continue;
      const float d = 1.0f / view.depth(x, y);
      kf.idepth(x, y) = d;
      kf.variance(x, y) = (0.01f * d) * (0.01f * d);
      sum += view.depth(x, y);
      ++count;
    }
  }
  kf.mean_depth = sum / count;
  return kf;
}

/// Rotation angle (degrees) and translation error of T_est relative to T_true.
struct PoseError {
  double rotation_deg;
  double translation;
};
inline PoseError ComparePoses(const SE3d& T_est, const SE3d& T_true) {
  const SE3d error = T_true.Inverse() * T_est;
  return {error.Rotation().Log().norm() * 180.0 / 3.14159265358979, error.Translation().norm()};
}

}  // namespace parallax::test
