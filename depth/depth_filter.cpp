#include "depth/depth_filter.hpp"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

#include "core/check.hpp"
#include "core/divergence.hpp"
#include "core/mask_scan.hpp"

namespace parallax {
namespace {

constexpr std::size_t Idx(int i) { return static_cast<std::size_t>(i); }

/// In place: each pixel becomes the sum of the 5x5 window around it (pixels within 2 of the
/// border, whose window leaves the image, become 0; callers skip them). Rows in parallel;
/// `row_sums` is working memory.
void BoxSum5x5(int w, int h, std::vector<float>* image, std::vector<float>* row_sums) {
  std::vector<float>& v = *image;
  std::vector<float>& rows = *row_sums;
  rows.resize(v.size());  // only the entries written below are read
  const auto at = [w](int x, int y) { return static_cast<std::size_t>(y) * Idx(w) + Idx(x); };
  tbb::parallel_for(0, h, [&](int y) {
    for (int x = 2; x < w - 2; ++x) {
      const std::size_t i = at(x, y);
      rows[i] = v[i - 2] + v[i - 1] + v[i] + v[i + 1] + v[i + 2];
    }
  });
  const std::size_t stride = Idx(w);
  tbb::parallel_for(0, h, [&](int y) {
    const bool inside = y >= 2 && y < h - 2;
    for (int x = 0; x < w; ++x) {
      const std::size_t i = at(x, y);
      v[i] = inside && x >= 2 && x < w - 2 ? rows[i - 2 * stride] + rows[i - stride] + rows[i] +
                                                 rows[i + stride] + rows[i + 2 * stride]
                                           : 0.0f;
    }
  });
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
  total->diverged += s.diverged;
  total->converged_skipped += s.converged_skipped;
}

}  // namespace

DepthFilter::DepthFilter(const DepthFilterOptions& options)
    : options_(options),
      converged_sigma_sq_(options.converged_relative_sigma * options.converged_relative_sigma),
      converged_recheck_(static_cast<std::uint32_t>(std::max(1, options.converged_recheck))) {
  options_.Check();
}

int DepthFilter::PlanRow(const InverseDepthMap& map, int y, const std::uint8_t* recheck_turn,
                         std::uint8_t* plan, DepthUpdateStats* stats) const {
  const std::size_t row = map.Index(0, y);
  const std::uint8_t* eligible = &map.eligible[row];
  const std::int16_t* blacklist = &map.blacklist[row];
  const std::uint8_t* valid = &map.valid[row];
  const float* idepth = &map.idepth[row];
  const float* variance = &map.variance[row];
  const float converged_sigma_sq = converged_sigma_sq_;
  const int w = map.Width();  // a local: the byte stores could alias the map
  int attempted = 0, diverged = 0, converged_skipped = 0, skipped = 0, planned = 0;
  // Branch-free, so that it vectorises: every quantity is computed for every pixel (those of
  // pixels without an estimate are discarded).
  for (int x = 0; x < w; ++x) {
    const float d = idepth[x], v = variance[x];
    const bool attempt = (eligible[x] != 0) & (blacklist[x] >= -1);
    const bool prior = valid[x] != 0;
    const bool healthy = HealthyEstimate(d, v, 1.0f / v);
    const bool converged = v < converged_sigma_sq * d * d;
    // A diverged prior would steer the search with NaN bounds.
    const bool is_diverged = attempt & prior & !healthy;
    // In turn, one in converged_recheck_ of the converged estimates per update.
    const bool not_its_turn = attempt & prior & healthy & converged & (recheck_turn[x] == 0);
    const bool go_on = attempt & !is_diverged & !not_its_turn;
    const bool observe = go_on & (plan[x] != 0);  // plan: MarkSearchableRow's answer
    attempted += static_cast<int>(attempt);
    diverged += static_cast<int>(is_diverged);
    converged_skipped += static_cast<int>(not_its_turn);
    skipped += static_cast<int>(go_on & !observe);  // what Observe would answer first
    planned += static_cast<int>(observe | is_diverged);
    plan[x] = static_cast<std::uint8_t>(static_cast<int>(observe) * kPlanObserve +
                                        static_cast<int>(is_diverged) * kPlanInvalidate);
  }
  stats->attempted += attempted;
  stats->diverged += diverged;
  stats->converged_skipped += converged_skipped;
  stats->skipped += skipped;
  return planned;
}

void DepthFilter::ObserveAndFuse(InverseDepthMap* map, const EpipolarSearch& search, int x, int y,
                                 DepthUpdateStats* stats) const {
  const std::size_t i = map->Index(x, y);
  const bool has_prior = map->valid[i] != 0;
  const StereoObservation obs = ObservePixel(*map, search, x, y, has_prior);
  if (obs.status != StereoStatus::kOk) {
    RecordFailure(map, i, has_prior, obs.status, stats);
  } else if (!has_prior) {
    CreateEstimate(map, i, obs, stats);
  } else {
    FuseObservation(map, x, y, obs, stats);
  }
}

StereoObservation DepthFilter::ObservePixel(const InverseDepthMap& map,
                                            const EpipolarSearch& search, int x, int y,
                                            bool has_prior) const {
  if (has_prior) {
    const std::size_t i = map.Index(x, y);
    const float mu = map.idepth[i], sigma = std::sqrt(map.variance[i]);
    return search.Observe(x, y, std::max(options_.min_idepth, mu - 2.0f * sigma),
                          std::min(options_.max_idepth, mu + 2.0f * sigma), mu,
                          options_.max_search_length);
  }
  const float mid = std::sqrt(options_.min_idepth * options_.max_idepth);
  return search.Observe(x, y, options_.min_idepth, options_.max_idepth, mid,
                        options_.max_search_length_new);
}

void DepthFilter::RecordFailure(InverseDepthMap* map, std::size_t i, bool has_prior,
                                StereoStatus status, DepthUpdateStats* stats) const {
  switch (status) {
    case StereoStatus::kOk:
      return;
    case StereoStatus::kAmbiguous:
      ++stats->ambiguous;
      if (!has_prior) {
        --map->blacklist[i];  // LSD-SLAM's rule: two failed creations end the tries
        return;
      }
      map->validity[i] -= options_.validity_gain;
      map->variance[i] *= options_.inconsistency_variance_factor;
      if (map->variance[i] > options_.max_variance) {
        map->Invalidate(i);
        --map->blacklist[i];
        ++stats->dropped;
      }
      return;
    case StereoStatus::kNoMatch:
      ++stats->no_match;
      if (!has_prior) --map->blacklist[i];
      return;
    case StereoStatus::kOutOfImage:
      ++stats->out_of_image;
      return;
    case StereoStatus::kSkipped:
      ++stats->skipped;
      return;
  }
}

void DepthFilter::CreateEstimate(InverseDepthMap* map, std::size_t i, const StereoObservation& obs,
                                 DepthUpdateStats* stats) const {
  if (!HealthyEstimate(obs.idepth, obs.variance)) {
    ++stats->diverged;
    return;
  }
  map->idepth[i] = obs.idepth;
  map->variance[i] = obs.variance;
  map->validity[i] = options_.initial_validity;
  map->valid[i] = obs.variance <= options_.max_variance;
  map->observations[i] = map->valid[i];
  stats->created += map->valid[i];
}

void DepthFilter::FuseObservation(InverseDepthMap* map, int x, int y, const StereoObservation& obs,
                                  DepthUpdateStats* stats) const {
  const std::size_t i = map->Index(x, y);
  // Kalman fusion with a consistency test (chi^2 at one sigma of the combined variance).
  const float prior_var = map->variance[i] * options_.process_noise_factor;
  const float diff = obs.idepth - map->idepth[i];
  if (diff * diff > obs.variance + prior_var) {
    ++stats->inconsistent;
    map->variance[i] *= options_.inconsistency_variance_factor;
    map->validity[i] -= options_.validity_gain;
    if (map->variance[i] > options_.max_variance) {
      map->Invalidate(i);
      ++stats->dropped;
    }
    return;
  }
  map->idepth[i] =
      (prior_var * obs.idepth + obs.variance * map->idepth[i]) / (prior_var + obs.variance);
  map->variance[i] = prior_var * obs.variance / (prior_var + obs.variance);
  if (!HealthyEstimate(map->idepth[i], map->variance[i])) {
    map->Invalidate(i);
    ++stats->diverged;
    return;
  }
  const float g = std::sqrt(map->Keyframe().Level(0).GradSq(x, y));
  map->validity[i] =
      std::min(map->validity[i] + options_.validity_gain, 5.0f + 250.0f * g / 255.0f);
  if (map->observations[i] < 65535) ++map->observations[i];
  ++stats->fused;
}

DepthUpdateStats DepthFilter::Update(InverseDepthMap* map, const StereoFrame& frame) const {
  CheckArgument(frame.frame != nullptr, "DepthFilter::Update: no frame");
  CheckArgument(frame.frame->IntensityLevel(0).Width() == map->Width() &&
                    frame.frame->IntensityLevel(0).Height() == map->Height(),
                "DepthFilter::Update: frame and keyframe sizes differ");
  const EpipolarSearch search(map->Keyframe(), frame, options_);
  const int w = map->Width();
  std::vector<DepthUpdateStats> per_row(static_cast<std::size_t>(map->Height()));
  // Whose turn a converged estimate's re-observation is: pixel i's when (i + updates) is a
  // multiple of converged_recheck_ (a map has fewer than 2^32 - pixels updates, so the 32-bit
  // sum does not wrap), i.e. recheck_turns[(row's start + updates) % recheck + x].
  std::vector<std::uint8_t>& turns = map->scratch.recheck_turns;
  turns.resize(Idx(w) + converged_recheck_);
  for (std::size_t k = 0; k < turns.size(); ++k)
    turns[k] = static_cast<std::uint8_t>(k % converged_recheck_ == 0);
  map->scratch.update_plan.resize(map->valid.size());  // every entry read is written below
  tbb::parallel_for(0, map->Height(), [&](int y) {
    DepthUpdateStats& s = per_row[static_cast<std::size_t>(y)];
    const std::size_t row = map->Index(0, y);
    std::uint8_t* plan = &map->scratch.update_plan[row];
    search.MarkSearchableRow(y, plan);
    const std::uint32_t phase =
        (static_cast<std::uint32_t>(row) + map->updates) % converged_recheck_;
    if (PlanRow(*map, y, &turns[phase], plan, &s) == 0) return;
    // Most pixels end in the plan, in runs.
    ForEachColumnNearMask(plan, 0, w, [&](int x) {
      if (plan[x] == kPlanObserve) {
        ObserveAndFuse(map, search, x, y, &s);
      } else if (plan[x] == kPlanInvalidate) {
        map->Invalidate(row + Idx(x));
      }
    });
  });
  ++map->updates;
  DepthUpdateStats total;
  for (const DepthUpdateStats& s : per_row) Add(&total, s);
  total.diverged += Regularize(map);
  return total;
}

int DepthFilter::FillHoles(InverseDepthMap* map) const {
  const int w = map->Width(), h = map->Height();
  const std::size_t n = map->valid.size();
  // Sums over the valid pixels of each 5x5 window of validity, inverse variance and inverse
  // depth / variance: box filters of the masked maps (separable, a few additions per pixel
  // instead of 25 neighbour visits for each of the ~200k empty eligible pixels).
  // The map's working memory: every entry is written below.
  std::vector<float>& support = map->scratch.fill[0];
  std::vector<float>& sum_w = map->scratch.fill[1];
  std::vector<float>& sum_wd = map->scratch.fill[2];
  std::vector<float>& row_sums = map->scratch.fill[3];
  for (std::vector<float>* plane : {&support, &sum_w, &sum_wd}) plane->resize(n);
  tbb::parallel_for(0, h, [&](int y) {
    for (std::size_t i = map->Index(0, y), end = i + Idx(w); i < end; ++i) {
      support[i] = sum_w[i] = sum_wd[i] = 0.0f;
      if (!map->valid[i]) continue;
      support[i] = map->validity[i];
      sum_w[i] = 1.0f / map->variance[i];
      sum_wd[i] = map->idepth[i] * sum_w[i];
    }
  });
  for (std::vector<float>* image : {&support, &sum_w, &sum_wd}) {
    BoxSum5x5(w, h, image, &row_sums);
  }
  // The window sums were taken before any filling, so filling a pixel here changes no other
  // pixel's decision: rows in parallel, counted in row order.
  std::vector<int> filled_in_row(Idx(h), 0);
  tbb::parallel_for(2, h - 2, [&](int y) {
    for (int x = 2; x < w - 2; ++x) {
      const std::size_t i = map->Index(x, y);
      if (map->valid[i] || !map->eligible[i]) continue;
      const bool allowed = map->blacklist[i] >= -1 || support[i] > 100.0f;
      if (!(support[i] > options_.fill_validity && allowed)) continue;
      const float d = sum_wd[i] / sum_w[i];
      map->idepth[i] = map->idepth_smoothed[i] = d;
      map->variance[i] = map->variance_smoothed[i] = options_.initial_variance * d * d;
      map->validity[i] = options_.initial_validity;
      map->observations[i] = 0;
      map->valid[i] = 1;
      ++filled_in_row[Idx(y)];
    }
  });
  int filled = 0;
  for (const int count : filled_in_row) filled += count;
  return filled;
}

float DepthFilter::NormalizeScale(InverseDepthMap* map) const {
  const double mean = map->MeanSmoothedIdepth();
  if (!std::isfinite(mean)) {
    throw NumericalDivergence("depth map: the mean inverse depth is not finite");
  }
  if (!(mean > 0.0)) return 1.0f;
  const auto s = static_cast<float>(1.0 / mean);
  map->Rescale(s);
  return s;
}

}  // namespace parallax
