// DepthFilter::Propagate: moving an inverse-depth map into a new keyframe.

#include <cmath>

#include "core/check.hpp"
#include "core/divergence.hpp"
#include "depth/depth_filter.hpp"

namespace parallax {

InverseDepthMap DepthFilter::Propagate(const InverseDepthMap& old_map,
                                       const std::shared_ptr<const Frame>& new_keyframe,
                                       const SE3d& T_new_old, float gain, float offset,
                                       PropagationStats* stats) const {
  CheckArgument(new_keyframe != nullptr, "DepthFilter::Propagate: no keyframe");
  InverseDepthMap map(new_keyframe, options_);
  CheckArgument(map.Width() == old_map.Width() && map.Height() == old_map.Height(),
                "DepthFilter::Propagate: keyframe sizes differ");
  PropagationStats local;
  PropagationStats& st = stats ? *stats : local;
  st = PropagationStats{};
  const PinholeCamera& K = new_keyframe->Camera(0);
  const PyramidLevel& old_image = old_map.Keyframe().Level(0);
  const PyramidLevel& new_image = new_keyframe->Level(0);
  const Eigen::Matrix3d R = T_new_old.RotationMatrix();
  const Eigen::Vector3d t = T_new_old.Translation();
  for (int y = 0; y < old_map.Height(); ++y) {
    for (int x = 0; x < old_map.Width(); ++x) {
      const std::size_t i = old_map.Index(x, y);
      if (!old_map.valid[i]) continue;
      ++st.source;
      if (!HealthyEstimate(old_map.idepth[i], old_map.variance[i])) {
        ++st.diverged;
        continue;
      }
      const double d_old = old_map.idepth[i];
      const Eigen::Vector3d p = R * (K.Unproject(Eigen::Vector2d(x, y)) / d_old) + t;
      if (!(p.z() > 0.0)) {
        ++st.out_of_view;
        continue;
      }
      const Eigen::Vector2d uv = K.Project(p);
      const int nx = static_cast<int>(std::lround(uv.x())),
                ny = static_cast<int>(std::lround(uv.y()));
      if (nx < 3 || ny < 3 || nx >= map.Width() - 3 || ny >= map.Height() - 3) {
        ++st.out_of_view;
        continue;
      }
      const std::size_t j = map.Index(nx, ny);
      // The point must land on texture that looks like it (occlusions and moving objects).
      const float expected = gain * old_image.intensity(x, y) + offset;
      const float tolerance = 20.0f + 0.7f * std::sqrt(new_image.grad_sq(nx, ny));
      if (!map.eligible[j] || std::abs(new_image.intensity(nx, ny) - expected) > tolerance) {
        ++st.rejected;
        continue;
      }
      const auto d_new = static_cast<float>(1.0 / p.z());
      const float ratio = d_new / static_cast<float>(d_old);
      const float var_new = ratio * ratio * ratio * ratio * old_map.variance[i];
      if (map.valid[j]) {
        const float diff = d_new - map.idepth[j];
        if (diff * diff > var_new + map.variance[j]) {
          ++st.occluded;  // two surfaces: the nearer one is visible
          if (d_new <= map.idepth[j]) continue;
        } else {
          ++st.merged;
          const float fused =
              (map.idepth[j] * var_new + d_new * map.variance[j]) / (var_new + map.variance[j]);
          map.variance[j] = var_new * map.variance[j] / (var_new + map.variance[j]);
          map.idepth[j] = fused;
          map.validity[j] += old_map.validity[i];
          map.observations[j] = static_cast<std::uint16_t>(
              std::min(65535, map.observations[j] + old_map.observations[i]));
          continue;
        }
      } else {
        ++st.propagated;
      }
      map.idepth[j] = d_new;
      map.variance[j] = var_new;
      map.validity[j] = old_map.validity[i];
      map.blacklist[j] = old_map.blacklist[i];
      map.observations[j] = old_map.observations[i];
      map.valid[j] = 1;
    }
  }
  for (std::size_t i = 0; i < map.valid.size(); ++i) {
    map.idepth_smoothed[i] = map.idepth[i];
    map.variance_smoothed[i] = map.variance[i];
  }
  st.diverged += Regularize(&map);
  FillHoles(&map);
  st.diverged += Regularize(&map);
  return map;
}

}  // namespace parallax
