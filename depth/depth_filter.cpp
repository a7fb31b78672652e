#include "depth/depth_filter.hpp"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

#include "core/check.hpp"

namespace parallax {
namespace {

void Invalidate(InverseDepthMap* map, std::size_t i) {
  map->valid[i] = 0;
  map->validity[i] = 0.0f;
  map->observations[i] = 0;
}

void Add(DepthUpdateStats* total, const DepthUpdateStats& s) {
  total->attempted += s.attempted;
  total->created += s.created;
  total->fused += s.fused;
  total->inconsistent += s.inconsistent;
  total->dropped += s.dropped;
  total->ambiguous += s.ambiguous;
  total->no_match += s.no_match;
  total->out_of_image += s.out_of_image;
  total->skipped += s.skipped;
}

}  // namespace

DepthFilter::DepthFilter(const DepthFilterOptions& options) : options_(options) {
  options_.Check();
}

void DepthFilter::UpdatePixel(InverseDepthMap* map, const EpipolarSearch& search, int x, int y,
                              DepthUpdateStats* stats) const {
  const std::size_t i = map->Index(x, y);
  if (!map->eligible[i] || map->blacklist[i] < -1) return;
  ++stats->attempted;
  const bool has_prior = map->valid[i] != 0;
  StereoObservation obs;
  if (has_prior) {
    const float mu = map->idepth[i], sigma = std::sqrt(map->variance[i]);
    obs = search.Observe(x, y, std::max(options_.min_idepth, mu - 2.0f * sigma),
                         std::min(options_.max_idepth, mu + 2.0f * sigma), mu,
                         options_.max_search_length);
  } else {
    const float mid = std::sqrt(options_.min_idepth * options_.max_idepth);
    obs = search.Observe(x, y, options_.min_idepth, options_.max_idepth, mid,
                         options_.max_search_length_new);
  }
  switch (obs.status) {
    case StereoStatus::kOk:
      break;
    case StereoStatus::kAmbiguous:
      ++stats->ambiguous;
      if (has_prior) {
        map->validity[i] -= options_.validity_gain;
        map->variance[i] *= options_.inconsistency_variance_factor;
        if (map->variance[i] > options_.max_variance) {
          Invalidate(map, i);
          --map->blacklist[i];
          ++stats->dropped;
        }
      }
      return;
    case StereoStatus::kNoMatch:
      ++stats->no_match;
      return;
    case StereoStatus::kOutOfImage:
      ++stats->out_of_image;
      return;
    case StereoStatus::kSkipped:
      ++stats->skipped;
      return;
  }
  if (!has_prior) {
    map->idepth[i] = obs.idepth;
    map->variance[i] = obs.variance;
    map->validity[i] = options_.initial_validity;
    map->valid[i] = obs.variance <= options_.max_variance;
    map->observations[i] = map->valid[i];
    stats->created += map->valid[i];
    return;
  }
  // Kalman fusion with a consistency test (chi^2 at one sigma of the combined variance).
  const float prior_var = map->variance[i] * options_.process_noise_factor;
  const float diff = obs.idepth - map->idepth[i];
  if (diff * diff > obs.variance + prior_var) {
    ++stats->inconsistent;
    map->variance[i] *= options_.inconsistency_variance_factor;
    map->validity[i] -= options_.validity_gain;
    if (map->variance[i] > options_.max_variance) {
      Invalidate(map, i);
      ++stats->dropped;
    }
    return;
  }
  map->idepth[i] =
      (prior_var * obs.idepth + obs.variance * map->idepth[i]) / (prior_var + obs.variance);
  map->variance[i] = prior_var * obs.variance / (prior_var + obs.variance);
  const float g = std::sqrt(map->Keyframe().Level(0).grad_sq(x, y));
  map->validity[i] =
      std::min(map->validity[i] + options_.validity_gain, 5.0f + 250.0f * g / 255.0f);
  if (map->observations[i] < 65535) ++map->observations[i];
  ++stats->fused;
}

DepthUpdateStats DepthFilter::Update(InverseDepthMap* map, const StereoFrame& frame) const {
  CheckArgument(frame.frame != nullptr, "DepthFilter::Update: no frame");
  CheckArgument(frame.frame->Level(0).Width() == map->Width() &&
                    frame.frame->Level(0).Height() == map->Height(),
                "DepthFilter::Update: frame and keyframe sizes differ");
  const EpipolarSearch search(map->Keyframe(), frame, options_);
  std::vector<DepthUpdateStats> per_row(static_cast<std::size_t>(map->Height()));
  tbb::parallel_for(0, map->Height(), [&](int y) {
    DepthUpdateStats& s = per_row[static_cast<std::size_t>(y)];
    for (int x = 0; x < map->Width(); ++x) UpdatePixel(map, search, x, y, &s);
  });
  DepthUpdateStats total;
  for (const DepthUpdateStats& s : per_row) Add(&total, s);
  Regularize(map);
  return total;
}

void DepthFilter::Regularize(InverseDepthMap* map) const {
  const int w = map->Width(), h = map->Height();
  std::vector<std::uint8_t> keep(map->valid.size(), 0);
  // Valid pixels are eligible ones, which keep a 3-pixel border: the 5x5 window needs no
  // bounds checks.
  tbb::parallel_for(2, h - 2, [&](int y) {
    for (int x = 2; x < w - 2; ++x) {
      const std::size_t i = map->Index(x, y);
      if (!map->valid[i]) continue;
      double sum_w = 0.0, sum_wd = 0.0, support = 0.0, agree = 0.0, disagree = 0.0;
      for (int dy = -2; dy <= 2; ++dy) {
        for (int dx = -2; dx <= 2; ++dx) {
          const std::size_t j = map->Index(x + dx, y + dy);
          if (!map->valid[j]) continue;
          support += map->validity[j];
          const float diff = map->idepth[j] - map->idepth[i];
          const bool compatible = diff * diff <= map->variance[i] + map->variance[j];
          // Observed neighbours vote on whether this estimate is an outlier.
          if (j != i && map->observations[j] > 0)
            (compatible ? agree : disagree) += map->validity[j];
          if (!compatible) continue;
          // Inverse variance, decaying mildly with distance (scale-free form of LSD's
          // 1 / (var + dist^2 * REG_DIST_VAR)).
          const double weight = 1.0 / (map->variance[j] * (1.0 + 0.1 * (dx * dx + dy * dy)));
          sum_w += weight;
          sum_wd += weight * map->idepth[j];
        }
      }
      map->idepth_smoothed[i] = static_cast<float>(sum_wd / sum_w);
      map->variance_smoothed[i] = std::min(map->variance[i], static_cast<float>(1.0 / sum_w));
      // Removed: too little support around it, or observed neighbours mostly disagree (a
      // wrong match that later observations within its own mu +- 2 sigma cannot correct).
      keep[i] = support >= options_.min_neighbour_validity && !(disagree > agree);
    }
  });
  for (std::size_t i = 0; i < keep.size(); ++i) {
    if (map->valid[i] && !keep[i]) Invalidate(map, i);
  }
}

int DepthFilter::FillHoles(InverseDepthMap* map) const {
  const int w = map->Width(), h = map->Height();
  std::vector<std::uint8_t> fill(map->valid.size(), 0);
  std::vector<float> value(map->valid.size(), 0.0f);
  tbb::parallel_for(2, h - 2, [&](int y) {
    for (int x = 2; x < w - 2; ++x) {
      const std::size_t i = map->Index(x, y);
      if (map->valid[i] || !map->eligible[i]) continue;
      double support = 0.0, sum_w = 0.0, sum_wd = 0.0;
      for (int dy = -2; dy <= 2; ++dy) {
        for (int dx = -2; dx <= 2; ++dx) {
          const std::size_t j = map->Index(x + dx, y + dy);
          if (!map->valid[j]) continue;
          support += map->validity[j];
          sum_w += 1.0 / map->variance[j];
          sum_wd += map->idepth[j] / map->variance[j];
        }
      }
      const bool allowed = map->blacklist[i] >= -1 || support > 100.0;
      if (support > options_.fill_validity && allowed) {
        fill[i] = 1;
        value[i] = static_cast<float>(sum_wd / sum_w);
      }
    }
  });
  int filled = 0;
  for (std::size_t i = 0; i < fill.size(); ++i) {
    if (!fill[i]) continue;
    const float d = value[i];
    map->idepth[i] = map->idepth_smoothed[i] = d;
    map->variance[i] = map->variance_smoothed[i] = options_.initial_variance * d * d;
    map->validity[i] = options_.initial_validity;
    map->observations[i] = 0;
    map->valid[i] = 1;
    ++filled;
  }
  return filled;
}

float DepthFilter::NormalizeScale(InverseDepthMap* map) const {
  const double mean = map->MeanSmoothedIdepth();
  if (!(mean > 0.0)) return 1.0f;
  const auto s = static_cast<float>(1.0 / mean);
  map->Rescale(s);
  return s;
}

}  // namespace parallax
