#include "tracking/tracking_reference.hpp"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <optional>

#include "core/check.hpp"
#include "core/mask_scan.hpp"
#include "tracking/tracking_result.hpp"

namespace parallax {
namespace {

// Writes point k of `level` (its arrays already hold k + 1 entries or more).
void SetPoint(ReferenceLevel* level, std::size_t k, const PinholeCamera& camera,
              const PyramidLevel& image, int x, int y, float idepth, float variance) {
  level->u[k] = static_cast<float>(x);
  level->v[k] = static_cast<float>(y);
  level->ray_x[k] = static_cast<float>((x - camera.Cx()) / camera.Fx());
  level->ray_y[k] = static_cast<float>((y - camera.Cy()) / camera.Fy());
  level->idepth[k] = idepth;
  level->variance[k] = variance;
  level->intensity[k] = image.intensity(x, y);
}

void AddPoint(ReferenceLevel* level, const PinholeCamera& camera, const PyramidLevel& image, int x,
              int y, float idepth, float variance) {
  const std::size_t k = level->Size();
  for (const auto field : kReferenceLevelFields) (level->*field).emplace_back();
  SetPoint(level, k, camera, image, x, y, idepth, variance);
}

// Inverse-variance sums of the finer level's points in each pixel of the next coarser level
// (2x2 aggregation), added in the order the points come.
class CoarseSums {
 public:
  CoarseSums(int width, int height)
      : width_(width),
        height_(height),
        sum_w_(static_cast<std::size_t>(width) * static_cast<std::size_t>(height), 0.0),
        sum_wd_(sum_w_.size(), 0.0) {}

  void Add(int fine_x, int fine_y, float idepth, float variance) {
    const int x = fine_x / 2, y = fine_y / 2;
    if (x >= width_ || y >= height_) return;  // odd trailing row/column has no parent
    const std::size_t index = Index(x, y);
    const double weight = 1.0 / variance;
    sum_w_[index] += weight;
    sum_wd_[index] += weight * idepth;
  }

  // The coarse level's points, one per pixel with a contribution, in raster order. Rows in
  // parallel: counted, then written at their offsets.
  ReferenceLevel Emit(const Frame& frame, int coarse_level) const {
    const PyramidLevel& image = frame.Level(coarse_level);
    const PinholeCamera& camera = frame.Camera(coarse_level);
    // The 1-pixel border has no gradient (pyramid convention), so it cannot constrain tracking.
    const int first_row = 1, end_row = std::max(1, height_ - 1);
    std::vector<std::size_t> row_start(static_cast<std::size_t>(end_row) + 1, 0);
    tbb::parallel_for(first_row, end_row, [&](int y) {
      std::size_t n = 0;
      for (int x = 1; x < width_ - 1; ++x) n += sum_w_[Index(x, y)] > 0.0;
      row_start[static_cast<std::size_t>(y) + 1] = n;
    });
    for (std::size_t y = 1; y < row_start.size(); ++y) row_start[y] += row_start[y - 1];
    ReferenceLevel coarse;
    for (const auto field : kReferenceLevelFields) (coarse.*field).resize(row_start.back());
    tbb::parallel_for(first_row, end_row, [&](int y) {
      std::size_t k = row_start[static_cast<std::size_t>(y)];
      for (int x = 1; x < width_ - 1; ++x) {
        const std::size_t index = Index(x, y);
        if (sum_w_[index] <= 0.0) continue;
        SetPoint(&coarse, k++, camera, image, x, y,
                 static_cast<float>(sum_wd_[index] / sum_w_[index]),
                 static_cast<float>(1.0 / sum_w_[index]));
      }
    });
    return coarse;
  }

 private:
  std::size_t Index(int x, int y) const {
    return static_cast<std::size_t>(y) * static_cast<std::size_t>(width_) +
           static_cast<std::size_t>(x);
  }

  int width_, height_;
  std::vector<double> sum_w_, sum_wd_;
};

// Level l+1 from level l: inverse-variance weighted 2x2 aggregation.
ReferenceLevel Coarsen(const ReferenceLevel& fine, const Frame& frame, int coarse_level) {
  const PyramidLevel& image = frame.Level(coarse_level);
  CoarseSums sums(image.Width(), image.Height());
  for (std::size_t i = 0; i < fine.Size(); ++i) {
    sums.Add(static_cast<int>(fine.u[i]), static_cast<int>(fine.v[i]), fine.idepth[i],
             fine.variance[i]);
  }
  return sums.Emit(frame, coarse_level);
}

// What the level-0 pass gives: the points (when kept) and their inverse depths' sum.
struct Level0Scan {
  ReferenceLevel points;
  double idepth_sum = 0.0;
  std::size_t count = 0;
};

// Level 0's usable pixels: stored only when a tracker reads them (keep), summed into level 1
// (when given) as they are found. One task per pair of level-0 rows, which only it maps to:
// each level-1 pixel gets its contributions in raster order, as from a serial scan; the
// tasks' results are joined in row order.
Level0Scan ScanLevel0(const Frame& keyframe, const ReferenceDepth& depth,
                      const TrackingReferenceOptions& options, bool keep, CoarseSums* level1) {
  const PyramidLevel& level0 = keyframe.Level(0);
  const ImageF& max_gradient = keyframe.MaxGradient();
  const int b = options.border, w = level0.Width(), h = level0.Height();
  std::vector<Level0Scan> pairs(static_cast<std::size_t>((h + 1) / 2));
  tbb::parallel_for(0, (h + 1) / 2, [&](int pair) {
    Level0Scan& scan = pairs[static_cast<std::size_t>(pair)];
    for (int y = std::max(2 * pair, b); y < std::min(2 * pair + 2, h - b); ++y) {
      const std::size_t row = static_cast<std::size_t>(y) * static_cast<std::size_t>(w);
      const auto visit = [&](int x) {
        const std::size_t i = row + static_cast<std::size_t>(x);
        const float d = depth.idepth[i], var = depth.variance[i];
        const bool usable = (depth.valid == nullptr || depth.valid[i] != 0) && d > 0.0f &&
                            var > 0.0f && std::isfinite(d) && std::isfinite(var) &&
                            max_gradient(x, y) >= options.min_gradient;
        if (!usable) return;
        if (keep) AddPoint(&scan.points, keyframe.Camera(0), level0, x, y, d, var);
        if (level1 != nullptr) level1->Add(x, y, d, var);
        scan.idepth_sum += d;
        ++scan.count;
      };
      if (depth.valid != nullptr) {
        ForEachColumnNearMask(depth.valid + row, b, w - b, visit);  // valid: sparse, in runs
      } else {
        for (int x = b; x < w - b; ++x) visit(x);
      }
    }
  });
  Level0Scan all;
  for (const Level0Scan& scan : pairs) {
    all.idepth_sum += scan.idepth_sum;
    all.count += scan.count;
    for (const auto field : kReferenceLevelFields) {
      (all.points.*field)
          .insert((all.points.*field).end(), (scan.points.*field).begin(),
                  (scan.points.*field).end());
    }
  }
  return all;
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
  CheckOption(finest_level >= 0 && finest_level < kMaxPyramidLevels, "TrackingReferenceOptions",
              "finest_level", "must be in [0, 7]");
}

TrackingReference::TrackingReference(std::shared_ptr<const Frame> keyframe, const ImageF& idepth,
                                     const ImageF& variance,
                                     const TrackingReferenceOptions& options)
    : TrackingReference(
          std::move(keyframe),
          ReferenceDepth{idepth.Width(), idepth.Height(), idepth.Data(),
                         variance.Width() == idepth.Width() && variance.Height() == idepth.Height()
                             ? variance.Data()
                             : nullptr,
                         nullptr},
          options) {}

TrackingReference::TrackingReference(std::shared_ptr<const Frame> keyframe,
                                     const ReferenceDepth& depth,
                                     const TrackingReferenceOptions& options)
    : keyframe_(std::move(keyframe)) {
  options.Check();
  CheckArgument(keyframe_ != nullptr, "TrackingReference: keyframe is null");
  const PyramidLevel& level0 = keyframe_->Level(0);
  CheckArgument(depth.width == level0.Width() && depth.height == level0.Height() &&
                    depth.idepth != nullptr && depth.variance != nullptr,
                "TrackingReference: idepth/variance images must have the keyframe's size");
  finest_level_ = std::min(options.finest_level, keyframe_->NumLevels() - 1);
  std::optional<CoarseSums> level1;
  if (keyframe_->NumLevels() > 1) {
    level1.emplace(keyframe_->Level(1).Width(), keyframe_->Level(1).Height());
  }
  Level0Scan scan =
      ScanLevel0(*keyframe_, depth, options, finest_level_ == 0, level1 ? &*level1 : nullptr);
  mean_idepth_ =
      scan.count ? static_cast<float>(scan.idepth_sum / static_cast<double>(scan.count)) : 0.0f;
  levels_.push_back(std::move(scan.points));
  if (level1) levels_.push_back(level1->Emit(*keyframe_, 1));
  for (int l = 2; l < keyframe_->NumLevels(); ++l) {
    levels_.push_back(Coarsen(levels_.back(), *keyframe_, l));
  }
  for (int l = 1; l < finest_level_; ++l) levels_[static_cast<std::size_t>(l)] = ReferenceLevel{};
  for (ReferenceLevel& level : levels_) ThinLevel(options.max_points_per_level, &level);
}

}  // namespace parallax
