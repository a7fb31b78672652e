// DepthFilter::Propagate: moving an inverse-depth map into a new keyframe.

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include "core/check.hpp"
#include "core/divergence.hpp"
#include "depth/depth_filter.hpp"

namespace parallax {
namespace {

/// An old estimate (index i) moved into the new keyframe at pixel j.
struct Landing {
  std::size_t i = 0;
  std::size_t j = 0;
  float idepth = 0.0f;
  float variance = 0.0f;
};

/// Projects row y of the old map into the new keyframe: the estimates that land on texture
/// that looks like them (occlusions and moving objects do not), with the variance transported
/// as (d_new / d_old)^4.
void ProjectRow(const InverseDepthMap& old_map, const InverseDepthMap& map, const SE3d& T_new_old,
                float gain, float offset, int y, std::vector<Landing>* landings,
                PropagationStats* st) {
  const PinholeCamera& K = map.Keyframe().Camera(0);
  const PyramidLevel& old_image = old_map.Keyframe().Level(0);
  const PyramidLevel& new_image = map.Keyframe().Level(0);
  const Eigen::Matrix3d R = T_new_old.RotationMatrix();
  const Eigen::Vector3d t = T_new_old.Translation();
  for (int x = 0; x < old_map.Width(); ++x) {
    const std::size_t i = old_map.Index(x, y);
    if (!old_map.valid[i]) continue;
    ++st->source;
    if (!HealthyEstimate(old_map.idepth[i], old_map.variance[i])) {
      ++st->diverged;
      continue;
    }
    const double d_old = old_map.idepth[i];
    const Eigen::Vector3d p = R * (K.Unproject(Eigen::Vector2d(x, y)) / d_old) + t;
    if (!(p.z() > 0.0)) {
      ++st->out_of_view;
      continue;
    }
    const Eigen::Vector2d uv = K.Project(p);
    const int nx = static_cast<int>(std::lround(uv.x())),
              ny = static_cast<int>(std::lround(uv.y()));
    if (nx < 3 || ny < 3 || nx >= map.Width() - 3 || ny >= map.Height() - 3) {
      ++st->out_of_view;
      continue;
    }
    const std::size_t j = map.Index(nx, ny);
    const float expected = gain * old_image.intensity(x, y) + offset;
    const float tolerance = 20.0f + 0.7f * std::sqrt(new_image.GradSq(nx, ny));
    if (!map.eligible[j] || std::abs(new_image.intensity(nx, ny) - expected) > tolerance) {
      ++st->rejected;
      continue;
    }
    const auto d_new = static_cast<float>(1.0 / p.z());
    const float ratio = d_new / static_cast<float>(d_old);
    landings->push_back({i, j, d_new, ratio * ratio * ratio * ratio * old_map.variance[i]});
  }
}

/// Writes one landing into the new map: an empty pixel takes it; on a pixel already taken,
/// consistent estimates are fused and of inconsistent ones the nearer stays (it is visible).
void Land(const InverseDepthMap& old_map, const Landing& landing, InverseDepthMap* map,
          PropagationStats* st) {
  const std::size_t i = landing.i, j = landing.j;
  const float d_new = landing.idepth, var_new = landing.variance;
  if (map->valid[j]) {
    const float diff = d_new - map->idepth[j];
    if (diff * diff > var_new + map->variance[j]) {
      ++st->occluded;
      if (d_new <= map->idepth[j]) return;
    } else {
      ++st->merged;
      const float fused =
          (map->idepth[j] * var_new + d_new * map->variance[j]) / (var_new + map->variance[j]);
      map->variance[j] = var_new * map->variance[j] / (var_new + map->variance[j]);
      map->idepth[j] = fused;
      map->validity[j] += old_map.validity[i];
      map->observations[j] = static_cast<std::uint16_t>(
          std::min(65535, map->observations[j] + old_map.observations[i]));
      return;
    }
  } else {
    ++st->propagated;
  }
  map->idepth[j] = d_new;
  map->variance[j] = var_new;
  map->validity[j] = old_map.validity[i];
  map->blacklist[j] = old_map.blacklist[i];
  map->observations[j] = old_map.observations[i];
  map->valid[j] = 1;
}

}  // namespace

InverseDepthMap DepthFilter::Propagate(const InverseDepthMap& old_map,
                                       const std::shared_ptr<const Frame>& new_keyframe,
                                       const SE3d& T_new_old, float gain, float offset,
                                       PropagationStats* stats, MapScratch scratch) const {
  CheckArgument(new_keyframe != nullptr, "DepthFilter::Propagate: no keyframe");
  InverseDepthMap map(new_keyframe, options_, std::move(scratch));
  CheckArgument(map.Width() == old_map.Width() && map.Height() == old_map.Height(),
                "DepthFilter::Propagate: keyframe sizes differ");
  PropagationStats local;
  PropagationStats& st = stats ? *stats : local;
  st = PropagationStats{};
  // Where each old estimate lands is independent of the others: projected in parallel rows.
  // Collisions depend on the order in which estimates land, so they are resolved in one
  // pass in pixel order, the same for any thread count.
  std::vector<std::vector<Landing>> landings(static_cast<std::size_t>(old_map.Height()));
  std::vector<PropagationStats> row_stats(landings.size());
  tbb::parallel_for(0, old_map.Height(), [&](int y) {
    ProjectRow(old_map, map, T_new_old, gain, offset, y, &landings[static_cast<std::size_t>(y)],
               &row_stats[static_cast<std::size_t>(y)]);
  });
  for (std::size_t y = 0; y < landings.size(); ++y) {
    st.source += row_stats[y].source;
    st.diverged += row_stats[y].diverged;
    st.out_of_view += row_stats[y].out_of_view;
    st.rejected += row_stats[y].rejected;
    for (const Landing& landing : landings[y]) Land(old_map, landing, &map, &st);
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
