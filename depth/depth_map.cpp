#include "depth/depth_map.hpp"

#include <tbb/parallel_for.h>

#include <cmath>
#include <random>

#include "core/check.hpp"

namespace parallax {

void DepthFilterOptions::Check() const {
  const char* s = "DepthFilterOptions";
  CheckOption(min_gradient >= 0.0f, s, "min_gradient", "must be >= 0");
  CheckOption(pixel_noise_sigma > 0.0f, s, "pixel_noise_sigma", "must be > 0");
  CheckOption(min_idepth > 0.0f && max_idepth > min_idepth, s, "min_idepth/max_idepth",
              "need 0 < min < max");
  CheckOption(initial_variance > 0.0f && max_variance >= initial_variance, s, "initial_variance",
              "must be in (0, max_variance]");
  CheckOption(process_noise_factor >= 1.0f, s, "process_noise_factor", "must be >= 1");
  CheckOption(inconsistency_variance_factor >= 1.0f, s, "inconsistency_variance_factor",
              "must be >= 1");
  CheckOption(epipolar_line_sigma >= 0.0f, s, "epipolar_line_sigma", "must be >= 0");
  CheckOption(max_ssd > 0.0f, s, "max_ssd", "must be > 0");
  CheckOption(ambiguity_ratio >= 1.0f, s, "ambiguity_ratio", "must be >= 1");
  CheckOption(max_search_length >= 3.0f, s, "max_search_length", "must be >= 3");
  CheckOption(max_search_length_new >= 3.0f, s, "max_search_length_new", "must be >= 3");
  CheckOption(baseline_sigma >= 0.0f, s, "baseline_sigma", "must be >= 0");
  CheckOption(rotation_sigma >= 0.0f && rotation_sigma <= 1.0f, s, "rotation_sigma",
              "must be in [0, 1]");
  CheckOption(min_search_length >= 2.0f && min_search_length <= max_search_length, s,
              "min_search_length", "must be in [2, max_search_length]");
  CheckOption(min_rescale > 0.0f && max_rescale > min_rescale, s, "min_rescale/max_rescale",
              "need 0 < min < max");
  CheckOption(converged_relative_sigma >= 0.0f && converged_relative_sigma < 1.0f, s,
              "converged_relative_sigma", "must be in [0, 1)");
  CheckOption(converged_recheck >= 1, s, "converged_recheck", "must be >= 1");
}

InverseDepthMap::InverseDepthMap(std::shared_ptr<const Frame> keyframe,
                                 const DepthFilterOptions& options, MapScratch scratch_memory)
    : scratch(std::move(scratch_memory)),
      keyframe_(std::move(keyframe)),
      width_(0),
      height_(0),
      options_(options) {
  options_.Check();
  // The assignments below keep a recycled array's memory (same size, same capacity).
  RecycledArrays& r = scratch.recycled;
  idepth.swap(r.floats[0]);
  variance.swap(r.floats[1]);
  idepth_smoothed.swap(r.floats[2]);
  variance_smoothed.swap(r.floats[3]);
  validity.swap(r.floats[4]);
  blacklist.swap(r.blacklist);
  valid.swap(r.bytes[0]);
  eligible.swap(r.bytes[1]);
  observations.swap(r.observations);
  r = RecycledArrays{};
  CheckArgument(keyframe_ != nullptr, "InverseDepthMap: keyframe is null");
  width_ = keyframe_->Level(0).Width();
  height_ = keyframe_->Level(0).Height();
  // The regularisation lists columns as 16-bit numbers (MapScratch).
  CheckArgument(width_ <= 65536,
                "InverseDepthMap: images wider than 65536 pixels are not supported");
  const std::size_t n = static_cast<std::size_t>(width_) * static_cast<std::size_t>(height_);
  idepth.assign(n, 0.0f);
  variance.assign(n, 0.0f);
  idepth_smoothed.assign(n, 0.0f);
  variance_smoothed.assign(n, 0.0f);
  validity.assign(n, 0.0f);
  blacklist.assign(n, 0);
  valid.assign(n, 0);
  eligible.assign(n, 0);
  observations.assign(n, 0);
  const ImageF& max_gradient = keyframe_->MaxGradient();
  constexpr int kBorder = 3;  // the 5-sample pattern must stay inside the image
  for (int y = kBorder; y < height_ - kBorder; ++y) {
    for (int x = kBorder; x < width_ - kBorder; ++x) {
      eligible[Index(x, y)] = max_gradient(x, y) >= options_.min_gradient;
    }
  }
}

RecycledArrays InverseDepthMap::TakeArrays() {
  RecycledArrays r;
  r.floats = {std::move(idepth), std::move(variance), std::move(idepth_smoothed),
              std::move(variance_smoothed), std::move(validity)};
  r.blacklist = std::move(blacklist);
  r.bytes = {std::move(valid), std::move(eligible)};
  r.observations = std::move(observations);
  return r;
}

void InverseDepthMap::InitializeRandom(float mean_idepth) {
  CheckArgument(mean_idepth > 0.0f && std::isfinite(mean_idepth),
                "InitializeRandom: mean_idepth must be > 0");
  std::mt19937_64 rng(options_.seed);
  for (std::size_t i = 0; i < valid.size(); ++i) {
    // Uniform in [0.5, 1.5) from 24 random bits (std distributions are not portable).
    const float u = static_cast<float>(rng() >> 40) / 16777216.0f;
    if (!eligible[i]) continue;
    idepth[i] = idepth_smoothed[i] = (0.5f + u) * mean_idepth;
    variance[i] = variance_smoothed[i] = options_.initial_variance * mean_idepth * mean_idepth;
    validity[i] = options_.initial_validity;
    valid[i] = 1;
  }
}

void InverseDepthMap::InitializeFromPrior(const ImageF& prior_idepth,
                                          const ImageF& prior_variance) {
  CheckArgument(prior_idepth.Width() == width_ && prior_idepth.Height() == height_ &&
                    prior_variance.Width() == width_ && prior_variance.Height() == height_,
                "InitializeFromPrior: prior images must have the keyframe's size");
  for (std::size_t i = 0; i < valid.size(); ++i) {
    const float d = prior_idepth.Data()[i], v = prior_variance.Data()[i];
    valid[i] = eligible[i] && d > 0.0f && v > 0.0f && std::isfinite(d) && std::isfinite(v);
    if (!valid[i]) continue;
    idepth[i] = idepth_smoothed[i] = d;
    variance[i] = variance_smoothed[i] = v;
    validity[i] = options_.initial_validity;
    observations[i] = 1;  // a prior counts as one observation
  }
}

std::size_t InverseDepthMap::NumConfirmed() const {
  std::size_t n = 0;
  for (std::size_t i = 0; i < valid.size(); ++i) n += IsConfirmed(i);
  return n;
}

std::size_t InverseDepthMap::NumValid() const {
  std::size_t n = 0;
  for (const auto v : valid) n += v;
  return n;
}

std::size_t InverseDepthMap::NumEligible() const {
  std::size_t n = 0;
  for (const auto e : eligible) n += e;
  return n;
}

double InverseDepthMap::MeanSmoothedIdepth() const {
  // Rows in parallel, their sums added in row order: the same value for any thread count.
  std::vector<double> row_sum(static_cast<std::size_t>(height_), 0.0);
  std::vector<std::size_t> row_count(row_sum.size(), 0);
  tbb::parallel_for(0, height_, [&](int y) {
    double sum = 0.0;
    std::size_t n = 0;
    for (std::size_t i = Index(0, y), end = i + static_cast<std::size_t>(width_); i < end; ++i) {
      if (!valid[i]) continue;
      sum += idepth_smoothed[i];
      ++n;
    }
    row_sum[static_cast<std::size_t>(y)] = sum;
    row_count[static_cast<std::size_t>(y)] = n;
  });
  double sum = 0.0;
  std::size_t n = 0;
  for (std::size_t y = 0; y < row_sum.size(); ++y) {
    sum += row_sum[y];
    n += row_count[y];
  }
  return n ? sum / static_cast<double>(n) : 0.0;
}

void InverseDepthMap::Rescale(float s) {
  CheckArgument(s > 0.0f && std::isfinite(s),
                "InverseDepthMap::Rescale: scale must be finite and > 0");
  for (std::size_t i = 0; i < valid.size(); ++i) {
    idepth[i] *= s;
    idepth_smoothed[i] *= s;
    variance[i] *= s * s;
    variance_smoothed[i] *= s * s;
  }
}

void InverseDepthMap::ExportSmoothed(ImageF* out_idepth, ImageF* out_variance,
                                     bool confirmed_only) const {
  *out_idepth = ImageF(width_, height_, 0.0f);
  *out_variance = ImageF(width_, height_, 0.0f);
  for (std::size_t i = 0; i < valid.size(); ++i) {
    if (!valid[i] || (confirmed_only && !IsConfirmed(i))) continue;
    out_idepth->Data()[i] = idepth_smoothed[i];
    out_variance->Data()[i] = variance_smoothed[i];
  }
}

}  // namespace parallax
