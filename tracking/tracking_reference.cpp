#include "tracking/tracking_reference.hpp"

#include <cmath>

#include "core/check.hpp"

namespace parallax {
namespace {

void AddPoint(ReferenceLevel* level, const PinholeCamera& camera, const PyramidLevel& image, int x,
              int y, float idepth, float variance) {
  level->u.push_back(static_cast<float>(x));
  level->v.push_back(static_cast<float>(y));
  level->ray_x.push_back(static_cast<float>((x - camera.Cx()) / camera.Fx()));
  level->ray_y.push_back(static_cast<float>((y - camera.Cy()) / camera.Fy()));
  level->idepth.push_back(idepth);
  level->variance.push_back(variance);
  level->intensity.push_back(image.intensity(x, y));
}

// Level l+1 from level l: inverse-variance weighted 2x2 aggregation.
ReferenceLevel Coarsen(const ReferenceLevel& fine, const Frame& frame, int coarse_level) {
  const PyramidLevel& image = frame.Level(coarse_level);
  const int w = image.Width(), h = image.Height();
  std::vector<double> sum_w(static_cast<std::size_t>(w) * static_cast<std::size_t>(h), 0.0);
  std::vector<double> sum_wd(sum_w.size(), 0.0);
  for (std::size_t i = 0; i < fine.Size(); ++i) {
    const int x = static_cast<int>(fine.u[i]) / 2, y = static_cast<int>(fine.v[i]) / 2;
    if (x >= w || y >= h) continue;  // odd trailing row/column has no parent
    const auto index =
        static_cast<std::size_t>(y) * static_cast<std::size_t>(w) + static_cast<std::size_t>(x);
    const double weight = 1.0 / fine.variance[i];
    sum_w[index] += weight;
    sum_wd[index] += weight * fine.idepth[i];
  }
  ReferenceLevel coarse;
  const PinholeCamera& camera = frame.Camera(coarse_level);
  // The 1-pixel border has no gradient (pyramid convention), so it cannot constrain tracking.
  for (int y = 1; y < h - 1; ++y) {
    for (int x = 1; x < w - 1; ++x) {
      const auto index =
          static_cast<std::size_t>(y) * static_cast<std::size_t>(w) + static_cast<std::size_t>(x);
      if (sum_w[index] <= 0.0) continue;
      AddPoint(&coarse, camera, image, x, y, static_cast<float>(sum_wd[index] / sum_w[index]),
               static_cast<float>(1.0 / sum_w[index]));
    }
  }
  return coarse;
}

// Keeps `budget` of the level's points spread evenly over their raster order, so that the
// kept points sample the map like the full set (selecting the strongest gradients per cell
// was tried: TUM 6.0 -> 7.9 mm at 5,000 points, docs/benchmarks.md).
void ThinLevel(std::size_t budget, ReferenceLevel* level) {
  const std::size_t n = level->Size();
  if (budget == 0 || n <= budget) return;
  std::size_t kept = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if ((i + 1) * budget / n == i * budget / n) continue;
    for (const auto field : kReferenceLevelFields) (level->*field)[kept] = (level->*field)[i];
    ++kept;
  }
  for (const auto field : kReferenceLevelFields) (level->*field).resize(kept);
}

}  // namespace

void TrackingReferenceOptions::Check() const {
  CheckOption(std::isfinite(min_gradient) && min_gradient >= 0.0f, "TrackingReferenceOptions",
              "min_gradient", "must be >= 0");
  CheckOption(border >= 1, "TrackingReferenceOptions", "border", "must be >= 1");
}

TrackingReference::TrackingReference(std::shared_ptr<const Frame> keyframe, const ImageF& idepth,
                                     const ImageF& variance,
                                     const TrackingReferenceOptions& options)
    : keyframe_(std::move(keyframe)) {
  options.Check();
  CheckArgument(keyframe_ != nullptr, "TrackingReference: keyframe is null");
  const PyramidLevel& level0 = keyframe_->Level(0);
  CheckArgument(idepth.Width() == level0.Width() && idepth.Height() == level0.Height() &&
                    variance.Width() == level0.Width() && variance.Height() == level0.Height(),
                "TrackingReference: idepth/variance images must have the keyframe's size");
  const ImageF& max_gradient = keyframe_->MaxGradient();
  const int b = options.border;
  const auto usable = [&](int x, int y) {
    const float d = idepth(x, y), var = variance(x, y);
    return d > 0.0f && var > 0.0f && std::isfinite(d) && std::isfinite(var) &&
           max_gradient(x, y) >= options.min_gradient;
  };
  std::size_t count = 0;
  for (int y = b; y < level0.Height() - b; ++y) {
    for (int x = b; x < level0.Width() - b; ++x) count += usable(x, y);
  }
  ReferenceLevel points;
  points.Reserve(count);
  double idepth_sum = 0.0;
  for (int y = b; y < level0.Height() - b; ++y) {
    for (int x = b; x < level0.Width() - b; ++x) {
      if (!usable(x, y)) continue;
      AddPoint(&points, keyframe_->Camera(0), level0, x, y, idepth(x, y), variance(x, y));
      idepth_sum += idepth(x, y);
    }
  }
  mean_idepth_ =
      points.Size() ? static_cast<float>(idepth_sum / static_cast<double>(points.Size())) : 0.0f;
  levels_.push_back(std::move(points));
  for (int l = 1; l < keyframe_->NumLevels(); ++l) {
    levels_.push_back(Coarsen(levels_.back(), *keyframe_, l));
  }
  for (ReferenceLevel& level : levels_) ThinLevel(options.max_points_per_level, &level);
}

}  // namespace parallax
