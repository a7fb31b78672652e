#pragma once
// The per-keyframe inverse-depth filter: stereo updates with Kalman fusion, regularisation,
// hole filling, propagation to a new keyframe and scale normalisation
// (docs/math/depth_filter.md).

#include <array>
#include <cstdint>
#include <vector>

#include "core/frame.hpp"
#include "core/se3.hpp"
#include "depth/depth_map.hpp"
#include "depth/epipolar_search.hpp"

namespace parallax {

/// Counts of one stereo update.
struct DepthUpdateStats {
  int attempted = 0;
  int created = 0;       ///< new estimates from a full-range search
  int fused = 0;         ///< consistent observations fused into a prior
  int inconsistent = 0;  ///< observation far from the prior (variance inflated)
  int dropped = 0;       ///< estimates removed (variance beyond max_variance)
  int ambiguous = 0;
  int no_match = 0;
  int out_of_image = 0;
  int skipped = 0;  ///< gradient not along the epipolar line, or too much rescale
  /// Estimates removed because fusion or regularisation left them non-finite or
  /// non-positive (numerical divergence; 0 in every run measured so far).
  int diverged = 0;
  /// Converged estimates this update did not re-observe (DepthFilterOptions pixel budget).
  int converged_skipped = 0;
};

struct PropagationStats {
  int source = 0;      ///< valid pixels in the old map
  int propagated = 0;  ///< landed in the new keyframe with consistent intensity
  int out_of_view = 0;
  int rejected = 0;  ///< intensity mismatch or no gradient in the new keyframe
  int merged = 0;    ///< collisions fused
  int occluded = 0;  ///< collisions where the nearer point won
  /// Old-map estimates not moved because they were non-finite or non-positive (divergence).
  int diverged = 0;
};

class DepthFilter {
 public:
  explicit DepthFilter(const DepthFilterOptions& options = {});

  /// Observes every eligible pixel in `frame` (known pose): valid pixels search mu +- 2 sigma
  /// and fuse; invalid ones search the full range and are created. Pixels are independent,
  /// so rows run in parallel with deterministic results. Then regularises.
  DepthUpdateStats Update(InverseDepthMap* map, const StereoFrame& frame) const;

  /// Smoothed idepth/variance from compatible neighbours in a 5x5 window; pixels with too
  /// little neighbour support are removed (outliers). It ends every stage that changes a
  /// map, so it is also the map's divergence check: estimates that are not healthy
  /// (core/divergence.hpp) are removed first. Returns how many were.
  int Regularize(InverseDepthMap* map) const;
  /// Fills empty eligible pixels whose neighbourhood has enough valid support.
  int FillHoles(InverseDepthMap* map) const;

  /// Moves the map into a new keyframe (T_new_old: old keyframe -> new), transporting
  /// variances ((d_new/d_old)^4), resolving collisions (inconsistent: keep the nearer;
  /// consistent: fuse), then regularises and fills holes. `scratch` becomes the new map's
  /// working memory: pass the old map's when it is not updated again, so that no keyframe
  /// allocates its own.
  InverseDepthMap Propagate(const InverseDepthMap& old_map,
                            const std::shared_ptr<const Frame>& new_keyframe, const SE3d& T_new_old,
                            float gain = 1.0f, float offset = 0.0f,
                            PropagationStats* stats = nullptr, MapScratch scratch = {}) const;

  /// Rescales the map so the mean smoothed inverse depth is 1 and returns the factor s applied
  /// (idepth x s). The keyframe's world scale changes by 1/s; its Sim(3) pose must take it.
  /// Returns 1 and leaves the map unchanged when it has no estimates. Throws
  /// NumericalDivergence when the mean is not finite (the map diverged).
  float NormalizeScale(InverseDepthMap* map) const;

  const DepthFilterOptions& Options() const { return options_; }

 private:
  /// What a stereo update does at each pixel of row y (`plan`, on entry
  /// EpipolarSearch::MarkSearchableRow's answer): kPlanObserve, kPlanInvalidate (a diverged
  /// prior) or nothing (not eligible, blacklisted, a converged estimate whose turn it is not,
  /// or nothing to search), counting the pixels it settles. recheck_turn[x] != 0: a converged
  /// estimate at x is re-observed in this update. Returns the pixels left to act on.
  int PlanRow(const InverseDepthMap& map, int y, const std::uint8_t* recheck_turn,
              std::uint8_t* plan, DepthUpdateStats* stats) const;
  /// The stereo observation of pixel (x, y) and its consequence for the pixel's estimate.
  void ObserveAndFuse(InverseDepthMap* map, const EpipolarSearch& search, int x, int y,
                      DepthUpdateStats* stats) const;
  /// The epipolar search of pixel (x, y): within two sigma of its prior when it has one.
  StereoObservation ObservePixel(const InverseDepthMap& map, const EpipolarSearch& search, int x,
                                 int y, bool has_prior) const;
  /// Counts a failed observation of pixel i and applies its consequences (blacklisting,
  /// a weaker prior).
  void RecordFailure(InverseDepthMap* map, std::size_t i, bool has_prior, StereoStatus status,
                     DepthUpdateStats* stats) const;
  /// A new estimate at pixel i from its first observation.
  void CreateEstimate(InverseDepthMap* map, std::size_t i, const StereoObservation& obs,
                      DepthUpdateStats* stats) const;
  /// Kalman fusion of an observation with pixel (x, y)'s prior, or its rejection.
  void FuseObservation(InverseDepthMap* map, int x, int y, const StereoObservation& obs,
                       DepthUpdateStats* stats) const;
  /// Regularize's first pass over row y: removes its unhealthy estimates (returns how many),
  /// writes the kernel's inputs and the row's work lists (MapScratch).
  int PrepareRegularizeRow(InverseDepthMap* map, int y) const;
  /// Regularize's second pass: smooths the row's listed pixels and lists those to remove.
  /// Reads the inputs of rows y - 2 to y + 2, so every row must be prepared first.
  void RegularizeRow(InverseDepthMap* map, int y) const;
  static constexpr std::uint8_t kPlanObserve = 1, kPlanInvalidate = 2;
  DepthFilterOptions options_;
  float converged_sigma_sq_;
  std::uint32_t converged_recheck_;  ///< 32-bit, as the map's update count it divides
};

}  // namespace parallax
