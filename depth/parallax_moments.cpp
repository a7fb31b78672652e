#include "depth/parallax_moments.hpp"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include "core/mask_scan.hpp"

namespace parallax {

double ParallaxMoments::ImageDistance(const Eigen::Vector3d& t_kf_frame) const {
  if (!(rho2 > 0.0)) return 0.0;
  const double tx = t_kf_frame.x();
  const double ty = t_kf_frame.y();
  const double tz = t_kf_frame.z();
  // E[rho^2 ((tx - x tz)^2 + (ty - y tz)^2)], expanded.
  const double flow2 =
      (tx * tx + ty * ty) * rho2 - 2.0 * tz * (tx * rho2_x + ty * rho2_y) + tz * tz * rho2_r2;
  return std::sqrt(std::max(flow2, 0.0) / rho2) * mean_idepth;
}

ParallaxMoments ComputeParallaxMoments(const InverseDepthMap& map) {
  const PinholeCamera& camera = map.Keyframe().Camera(0);
  const int width = map.Width();
  const int height = map.Height();
  // Per row: count, sum rho, sum rho^2, sum rho^2 x, sum rho^2 y, sum rho^2 r^2.
  using RowSums = std::array<double, 6>;
  std::vector<RowSums> rows(static_cast<std::size_t>(height), RowSums{});
  const double inv_fx = 1.0 / camera.Fx();
  tbb::parallel_for(0, height, [&](int v) {
    const double y = (v - camera.Cy()) / camera.Fy();
    RowSums s{};
    const std::size_t row = map.Index(0, v);
    // Valid pixels are sparse and in runs.
    ForEachColumnNearMask(&map.valid[row], 0, width, [&](int u) {
      const std::size_t i = row + static_cast<std::size_t>(u);
      if (!map.valid[i]) return;
      const double x = (u - camera.Cx()) * inv_fx;
      const double rho = map.idepth_smoothed[i];
      const double rho2 = rho * rho;
      s[0] += 1.0;
      s[1] += rho;
      s[2] += rho2;
      s[3] += rho2 * x;
      s[4] += rho2 * y;
      s[5] += rho2 * (x * x + y * y);
    });
    rows[static_cast<std::size_t>(v)] = s;
  });
  RowSums total{};
  for (const RowSums& s : rows) {
    for (std::size_t k = 0; k < total.size(); ++k) total[k] += s[k];
  }
  ParallaxMoments m;
  if (total[0] == 0.0) return m;
  const double n = total[0];
  m.mean_idepth = total[1] / n;
  m.rho2 = total[2] / n;
  m.rho2_x = total[3] / n;
  m.rho2_y = total[4] / n;
  m.rho2_r2 = total[5] / n;
  return m;
}

}  // namespace parallax
