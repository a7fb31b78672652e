// DepthFilter::Regularize: smoothing over compatible neighbours and the outlier vote, after
// every stage that changes a map (LSD-SLAM's regularisation; docs/math/depth_filter.md).

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cstdint>
#include <vector>

#include "core/divergence.hpp"
#include "core/mask_scan.hpp"
#include "depth/depth_filter.hpp"
#include "depth/regularize_kernel.hpp"

namespace parallax {
namespace {

constexpr std::size_t Idx(int i) { return static_cast<std::size_t>(i); }

// The regularisation's passes over a row are branch-free over raw pointers, so that they
// vectorise: a third of the pixels are valid, in no predictable pattern. Invalid pixels'
// quotients are computed and discarded.

/// 1 / variance for every pixel of the row from index `row` (w pixels), into `inv_var`: a
/// division under a condition does not vectorise.
void InverseVariances(const InverseDepthMap& map, std::size_t row, int w, float* inv_var) {
  const float* variance = &map.variance[row];
  for (int x = 0; x < w; ++x) inv_var[x] = 1.0f / variance[x];
}

/// Valid estimates in the row that are not healthy, given the row's inverse variances.
int CountUnhealthy(const InverseDepthMap& map, std::size_t row, int w, const float* inv_var) {
  const std::uint8_t* valid = &map.valid[row];
  const float* idepth = &map.idepth[row];
  const float* variance = &map.variance[row];
  int unhealthy = 0;
  for (int x = 0; x < w; ++x) {
    const bool healthy = HealthyEstimate(idepth[x], variance[x], inv_var[x]);
    unhealthy += static_cast<int>((valid[x] != 0) & !healthy);
  }
  return unhealthy;
}

/// The kernel's inputs for the row from its inverse variances (in in->inv_var): 0 for
/// invalid pixels.
void MaskRegularizeInputs(const InverseDepthMap& map, std::size_t row, int w,
                          RegularizeInputs* in) {
  const std::uint8_t* valid = &map.valid[row];
  const std::uint16_t* observations = &map.observations[row];
  const float* validity = &map.validity[row];
  float* inv_var = &in->inv_var[row];
  float* support = &in->support[row];
  float* vote = &in->vote[row];
  for (int x = 0; x < w; ++x) {
    const bool is_valid = valid[x] != 0;
    const float quotient = inv_var[x], own_validity = validity[x];  // unconditional loads
    const float v = is_valid ? own_validity : 0.0f;
    inv_var[x] = is_valid ? quotient : 0.0f;
    support[x] = v;
    vote[x] = observations[x] != 0 ? v : 0.0f;
  }
}

}  // namespace

int DepthFilter::Regularize(InverseDepthMap* map) const {
  const int h = map->Height();
  MapScratch& scratch = map->scratch;
  const std::size_t n = map->valid.size();
  // The kernel's inputs once per pixel (0 for invalid ones), and the distance decay as a
  // table: the 5x5 window is then multiplications and masks only. The buffers are the map's,
  // reused: every pixel is written below.
  RegularizeInputs& in = scratch.regularize;
  in.width = map->Width();
  in.idepth = map->idepth.data();
  in.variance = map->variance.data();
  in.inv_var.resize(n);
  in.support.resize(n);
  in.vote.resize(n);
  scratch.valid_columns.resize(n);
  scratch.removed_columns.resize(n);
  scratch.valid_in_row.assign(Idx(h), 0);
  scratch.removed_in_row.assign(Idx(h), 0);
  // Inverse variance, decaying mildly with distance (scale-free form of LSD's
  // 1 / (var + dist^2 * REG_DIST_VAR)).
  for (int dy = -2; dy <= 2; ++dy) {
    for (int dx = -2; dx <= 2; ++dx)
      in.decay[Idx((dy + 2) * 5 + dx + 2)] =
          1.0f / (1.0f + 0.1f * static_cast<float>(dx * dx + dy * dy));
  }
  // Per pixel, so rows run in parallel; the count is summed in row order.
  std::vector<int> diverged_in_row(Idx(h), 0);
  tbb::parallel_for(0, h, [&](int y) { diverged_in_row[Idx(y)] = PrepareRegularizeRow(map, y); });
  int diverged = 0;
  for (const int count : diverged_in_row) diverged += count;
  tbb::parallel_for(0, h, [&](int y) { RegularizeRow(map, y); });
  // After every window has read its inputs: the removals change no other pixel's result.
  tbb::parallel_for(0, h, [&](int y) {
    const std::uint16_t* removed = &scratch.removed_columns[map->Index(0, y)];
    for (int k = 0; k < scratch.removed_in_row[Idx(y)]; ++k)
      map->Invalidate(map->Index(removed[k], y));
  });
  return diverged;
}

int DepthFilter::PrepareRegularizeRow(InverseDepthMap* map, int y) const {
  MapScratch& scratch = map->scratch;
  const int w = map->Width(), h = map->Height();
  const std::size_t row = map->Index(0, y);
  float* inv_var = &scratch.regularize.inv_var[row];
  InverseVariances(*map, row, w, inv_var);
  const int diverged = CountUnhealthy(*map, row, w, inv_var);
  if (diverged > 0) {  // rare
    for (int x = 0; x < w; ++x) {
      const std::size_t i = row + Idx(x);
      if (map->valid[i] != 0 && !HealthyEstimate(map->idepth[i], map->variance[i], inv_var[x]))
        map->Invalidate(i);
    }
  }
  MaskRegularizeInputs(*map, row, w, &scratch.regularize);
  const std::uint8_t* valid = &map->valid[row];
  // The work lists: valid pixels inside the window's margin are regularised; valid ones on
  // it (none where pixels are eligible only 3 or more from the border) are removed.
  const bool inner_row = y >= 2 && y < h - 2;
  std::uint16_t* inner = &scratch.valid_columns[row];
  std::uint16_t* removed = &scratch.removed_columns[row];
  int num_inner = 0, num_removed = 0;
  // Semi-dense maps have long runs without a valid pixel.
  ForEachColumnNearMask(valid, 0, w, [&](int x) {
    const bool is_valid = valid[x] != 0;
    const bool is_inner = inner_row && x >= 2 && x < w - 2;
    inner[num_inner] = removed[num_removed] = static_cast<std::uint16_t>(x);
    num_inner += static_cast<int>(is_valid && is_inner);
    num_removed += static_cast<int>(is_valid && !is_inner);
  });
  scratch.valid_in_row[Idx(y)] = num_inner;
  scratch.removed_in_row[Idx(y)] = num_removed;
  return diverged;
}

void DepthFilter::RegularizeRow(InverseDepthMap* map, int y) const {
  MapScratch& scratch = map->scratch;
  const std::size_t row = map->Index(0, y);
  const std::uint16_t* inner = &scratch.valid_columns[row];
  std::uint16_t* removed = &scratch.removed_columns[row];
  int& num_removed = scratch.removed_in_row[Idx(y)];
  for (int k = 0; k < scratch.valid_in_row[Idx(y)]; ++k) {
    const std::size_t i = row + inner[k];
    const RegularizedPixel r = RegularizePixelSimd(scratch.regularize, i);
    map->idepth_smoothed[i] = r.idepth;
    map->variance_smoothed[i] = r.variance;
    // Removed: too little support around it, or observed neighbours mostly disagree (a
    // wrong match that later observations within its own mu +- 2 sigma cannot correct).
    const bool keep = r.support >= options_.min_neighbour_validity && !(r.disagree > r.agree) &&
                      HealthyEstimate(r.idepth, r.variance);
    removed[num_removed] = inner[k];
    num_removed += static_cast<int>(!keep);
  }
}

}  // namespace parallax
