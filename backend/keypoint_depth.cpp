#include "backend/keypoint_depth.hpp"

#include <cmath>
#include <limits>

namespace parallax {

KeypointDepth::KeypointDepth(const FrozenDepth& depth, const PinholeCamera& camera,
                             double max_relative_std)
    : camera_(camera), max_relative_std_(max_relative_std) {
  depth.ToImages(&idepth_, &variance_);
}

std::optional<Eigen::Vector3d> KeypointDepth::Point(const Eigen::Vector2f& pixel) const {
  const int cx = static_cast<int>(std::lround(pixel.x()));
  const int cy = static_cast<int>(std::lround(pixel.y()));
  float best_variance = std::numeric_limits<float>::max();
  float best_idepth = 0.0f;
  for (int y = cy - 1; y <= cy + 1; ++y) {
    for (int x = cx - 1; x <= cx + 1; ++x) {
      if (!idepth_.Contains(x, y) || !(idepth_(x, y) > 0.0f) || variance_(x, y) >= best_variance) {
        continue;
      }
      best_variance = variance_(x, y);
      best_idepth = idepth_(x, y);
    }
  }
  if (!(best_idepth > 0.0f) || std::sqrt(best_variance) / best_idepth > max_relative_std_) {
    return std::nullopt;
  }
  return camera_.Unproject(pixel.cast<double>()) / static_cast<double>(best_idepth);
}

}  // namespace parallax
