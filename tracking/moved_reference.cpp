// TrackingReference::MovedTo: a keyframe's tracking points seen from another frame.

#include <cmath>
#include <cstdint>
#include <vector>

#include "core/check.hpp"
#include "tracking/tracking_reference.hpp"

namespace parallax {
namespace {

// One level's points moved into `image` (the same level of the other frame): the nearest
// landing per pixel, then emitted in raster order.
ReferenceLevel MoveLevel(const ReferenceLevel& from, const PyramidLevel& image,
                         const PinholeCamera& camera, const SE3d& T_to_kf, float gain,
                         float offset) {
  const int w = image.Width(), h = image.Height();
  const Eigen::Matrix3f R = T_to_kf.RotationMatrix().cast<float>();
  const Eigen::Vector3f t = T_to_kf.Translation().cast<float>();
  const auto fx = static_cast<float>(camera.Fx()), fy = static_cast<float>(camera.Fy()),
             cx = static_cast<float>(camera.Cx()), cy = static_cast<float>(camera.Cy());
  // Per pixel: the index of the point that landed there (-1: none).
  std::vector<std::int32_t> landed(static_cast<std::size_t>(w) * static_cast<std::size_t>(h), -1);
  std::vector<float> idepth(from.Size()), variance(from.Size());
  for (std::size_t i = 0; i < from.Size(); ++i) {
    const Eigen::Vector3f q =
        R * (Eigen::Vector3f(from.ray_x[i], from.ray_y[i], 1.0f) / from.idepth[i]) + t;
    if (!(q.z() > 0.0f)) continue;
    const long x = std::lround(fx * q.x() / q.z() + cx), y = std::lround(fy * q.y() / q.z() + cy);
    if (x < 1 || y < 1 || x >= w - 1 || y >= h - 1) continue;
    const auto xi = static_cast<int>(x), yi = static_cast<int>(y);
    const float expected = gain * from.intensity[i] + offset;
    const float tolerance = 20.0f + 0.7f * std::sqrt(image.GradSq(xi, yi));
    if (std::abs(image.intensity(xi, yi) - expected) > tolerance) continue;
    idepth[i] = 1.0f / q.z();
    const float ratio = idepth[i] / from.idepth[i];
    variance[i] = ratio * ratio * ratio * ratio * from.variance[i];
    std::int32_t& slot = landed[static_cast<std::size_t>(yi) * static_cast<std::size_t>(w) +
                                static_cast<std::size_t>(xi)];
    if (slot < 0 || idepth[static_cast<std::size_t>(slot)] < idepth[i]) {
      slot = static_cast<std::int32_t>(i);
    }
  }
  ReferenceLevel to;
  for (int y = 1; y < h - 1; ++y) {
    for (int x = 1; x < w - 1; ++x) {
      const std::int32_t slot = landed[static_cast<std::size_t>(y) * static_cast<std::size_t>(w) +
                                       static_cast<std::size_t>(x)];
      if (slot < 0) continue;
      const auto i = static_cast<std::size_t>(slot);
      to.u.push_back(static_cast<float>(x));
      to.v.push_back(static_cast<float>(y));
      // As TrackingReference's own points (tracking_reference.cpp, SetPoint).
      to.ray_x.push_back(static_cast<float>((x - camera.Cx()) / camera.Fx()));
      to.ray_y.push_back(static_cast<float>((y - camera.Cy()) / camera.Fy()));
      to.idepth.push_back(idepth[i]);
      to.variance.push_back(variance[i]);
      to.intensity.push_back(image.intensity(x, y));
    }
  }
  return to;
}

}  // namespace

TrackingReference::TrackingReference(std::shared_ptr<const Frame> keyframe,
                                     std::vector<ReferenceLevel> levels, int finest_level)
    : keyframe_(std::move(keyframe)), levels_(std::move(levels)), finest_level_(finest_level) {
  const ReferenceLevel& finest = levels_[static_cast<std::size_t>(finest_level_)];
  double sum = 0.0;
  for (const float d : finest.idepth) sum += d;
  mean_idepth_ =
      finest.Size() ? static_cast<float>(sum / static_cast<double>(finest.Size())) : 0.0f;
}

TrackingReference TrackingReference::MovedTo(std::shared_ptr<const Frame> to, const SE3d& T_to_kf,
                                             float gain, float offset) const {
  CheckArgument(to != nullptr && to->NumLevels() == NumLevels() &&
                    to->Level(0).Width() == keyframe_->Level(0).Width() &&
                    to->Level(0).Height() == keyframe_->Level(0).Height(),
                "TrackingReference::MovedTo: the frame's pyramid differs from the keyframe's");
  std::vector<ReferenceLevel> levels(levels_.size());
  for (int l = finest_level_; l < NumLevels(); ++l) {
    levels[static_cast<std::size_t>(l)] = MoveLevel(
        levels_[static_cast<std::size_t>(l)], to->Level(l), to->Camera(l), T_to_kf, gain, offset);
  }
  return TrackingReference(std::move(to), std::move(levels), finest_level_);
}

}  // namespace parallax
