#pragma once
// Per-keyframe inverse-depth map, structure-of-arrays over the keyframe's level-0 pixels.

#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include "core/frame.hpp"
#include "core/image.hpp"
#include "depth/depth_options.hpp"
#include "depth/regularize_kernel.hpp"

namespace parallax {

/// The per-pixel arrays of a map that is no longer kept, for the next map to reuse: their
/// memory is already resident, where fresh memory is first touched page by page
/// (docs/benchmarks.md, "Where a depth update and a keyframe spend their time").
struct RecycledArrays {
  std::array<std::vector<float>, 5> floats;
  std::vector<std::int16_t> blacklist;
  std::array<std::vector<std::uint8_t>, 2> bytes;
  std::vector<std::uint16_t> observations;
};

/// Working memory of the filter's passes over a map (DepthFilter::Regularize and FillHoles),
/// kept with the map so that a stereo update allocates nothing, and handed on to the map
/// propagated from it (DepthFilter::Propagate). Not map state: a copy starts empty, and
/// Release() returns the memory of a map that is no longer updated.
class MapScratch {
 public:
  MapScratch() = default;
  ~MapScratch() = default;
  MapScratch(const MapScratch& /*other*/) {}
  MapScratch& operator=(const MapScratch& /*other*/) { return *this; }
  MapScratch(MapScratch&&) noexcept = default;
  MapScratch& operator=(MapScratch&&) noexcept = default;

  void Release() { *this = MapScratch{}; }

  RegularizeInputs regularize;  ///< the kernel's per-pixel inputs
  /// The regularisation's work lists per row (row y's entries start at y * width): the
  /// columns of its valid pixels inside the 5x5 window's margin, and of those it removes.
  std::vector<std::uint16_t> valid_columns, removed_columns;
  std::vector<int> valid_in_row, removed_in_row;  ///< entries used per row
  /// Hole filling's window sums (support, inverse variance, inverse depth / variance) and
  /// its box filter's row sums.
  std::array<std::vector<float>, 4> fill;
  /// A stereo update's plan per pixel (DepthFilter::PlanRow) and whose turn a converged
  /// estimate's re-observation is, by column.
  std::vector<std::uint8_t> update_plan, recheck_turns;
  /// Arrays a new map built with this scratch takes instead of allocating its own.
  RecycledArrays recycled;
};

/// Per-pixel state of the inverse-depth filter (index = y * width + x). A pixel has an
/// estimate when valid[i] != 0; its raw idepth/variance are filtered by Kalman fusion and
/// the smoothed ones (regularised over compatible neighbours) are what tracking and
/// propagation use.
class InverseDepthMap {
 public:
  /// An empty map for `keyframe`: no estimates; pixels eligible where the 3x3 max gradient is
  /// >= options.min_gradient. The map keeps `scratch` as its working memory and takes the
  /// arrays recycled in it (if any) for its own.
  InverseDepthMap(std::shared_ptr<const Frame> keyframe, const DepthFilterOptions& options,
                  MapScratch scratch = {});

  const Frame& Keyframe() const { return *keyframe_; }
  const std::shared_ptr<const Frame>& KeyframePtr() const { return keyframe_; }
  int Width() const { return width_; }
  int Height() const { return height_; }
  std::size_t Index(int x, int y) const {
    return static_cast<std::size_t>(y) * static_cast<std::size_t>(width_) +
           static_cast<std::size_t>(x);
  }

  /// LSD-style start: every eligible pixel gets idepth uniform in [0.5, 1.5] * mean_idepth and
  /// variance initial_variance * mean_idepth^2 (deterministic for options.seed).
  void InitializeRandom(float mean_idepth = 1.0f);
  /// From a prior (sparse or dense): eligible pixels with prior idepth > 0 and variance > 0.
  void InitializeFromPrior(const ImageF& idepth, const ImageF& variance);

  /// Removes pixel i's estimate (its validity and observation count go with it; its depth
  /// and variance stay as the last values, unused).
  void Invalidate(std::size_t i) {
    valid[i] = 0;
    validity[i] = 0.0f;
    observations[i] = 0;
  }

  std::size_t NumValid() const;
  std::size_t NumEligible() const;
  /// Mean smoothed inverse depth of valid pixels (0 if none).
  double MeanSmoothedIdepth() const;
  /// Multiplies all inverse depths by s and variances by s^2 (scale change of the map).
  void Rescale(float s);
  /// Smoothed idepth and variance as images (0 where invalid, or unconfirmed when
  /// confirmed_only), e.g. for TrackingReference.
  void ExportSmoothed(ImageF* idepth, ImageF* variance, bool confirmed_only = false) const;

  // Per-pixel arrays (public for the filter stages; sized Width() * Height()).
  std::vector<float> idepth;
  std::vector<float> variance;
  std::vector<float> idepth_smoothed;
  std::vector<float> variance_smoothed;
  std::vector<float> validity;
  std::vector<std::int16_t> blacklist;  ///< < 0: repeatedly failed; skipped below -1
  std::vector<std::uint8_t> valid;
  std::vector<std::uint8_t> eligible;  ///< enough gradient to be estimated
  /// Stereo observations fused (or that created the estimate); 0 for random or hole-filled
  /// values, which are hypotheses until observed.
  std::vector<std::uint16_t> observations;
  /// Stereo updates made on this map (DepthFilter::Update): picks which converged estimates
  /// an update re-observes (DepthFilterOptions::converged_recheck).
  std::uint32_t updates = 0;
  /// The filter's working memory (see MapScratch); empty in a copy.
  MapScratch scratch;

  /// Moves the per-pixel arrays out for a later map (RecycledArrays); the map is empty after.
  RecycledArrays TakeArrays();

  /// Valid with at least one stereo observation (or from a prior).
  bool IsConfirmed(std::size_t i) const { return valid[i] && observations[i] > 0; }
  std::size_t NumConfirmed() const;

 private:
  std::shared_ptr<const Frame> keyframe_;
  int width_;
  int height_;
  DepthFilterOptions options_;
};

}  // namespace parallax
