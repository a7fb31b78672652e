#pragma once
// Options of the inverse-depth filter (depth/). Defaults follow LSD-SLAM's DepthMap where
// they are scale-independent; inverse-depth limits are in the map's units (1/unit).

#include <cstdint>

namespace parallax {

struct DepthFilterOptions {
  /// Pixels whose 3x3 max gradient is below this are never estimated (grey levels / pixel).
  /// LSD-SLAM uses 5; 8 leaves out the weakest third of the pixels, whose stereo variance is
  /// largest, for ~25% less mapping time at the same accuracy (docs/benchmarks.md).
  float min_gradient = 8.0f;
  /// Image noise sigma_I (grey levels).
  float pixel_noise_sigma = 4.0f;
  /// Inverse-depth search range for new pixels, 1/unit.
  float min_idepth = 1e-3f;
  float max_idepth = 20.0f;
  /// Variance of a random initialisation and of hole-filled pixels (relative to idepth^2 of
  /// the mean inverse depth 1: LSD's 0.5 * MAX_VAR).
  float initial_variance = 0.125f;
  /// An estimate whose variance exceeds this is dropped (LSD's MAX_VAR).
  float max_variance = 0.25f;
  /// Multiplicative process noise applied to the prior variance before each fusion.
  float process_noise_factor = 1.01f;
  /// Inconsistent observation: prior variance x this.
  float inconsistency_variance_factor = 1.1f;
  /// Position uncertainty of the epipolar line, pixels (pose error), per unit tracking
  /// residual quality (LSD's 0.25 * (1 + residual)).
  float epipolar_line_sigma = 0.25f;
  /// SSD over 5 samples: reject the best match above this plus 20 sqrt(gradient along line).
  float max_ssd = 1300.0f;
  /// Ambiguous when a non-adjacent runner-up is below this factor times the best SSD.
  float ambiguity_ratio = 1.5f;
  /// Longest searched epipolar segment for a pixel with a prior, pixels.
  float max_search_length = 30.0f;
  /// Longest segment of the full-range search for a new pixel, pixels (centred on the
  /// geometric mean of min/max inverse depth; like every window it must fit in the frame).
  float max_search_length_new = 120.0f;
  /// Shortest searched segment, pixels (LSD-SLAM's MIN_EPL_LENGTH_CROP); every segment is also
  /// padded by a pixel beyond each end of the prior's range.
  float min_search_length = 3.0f;
  /// Gates: squared gradient along the epipolar line >= this, and its share of |grad|^2.
  float min_gradient_along_line_sq = 4.0f;
  float min_gradient_along_line_share = 0.09f;
  /// Uncertainty of a tracked frame's baseline, in the map's units (mean depth 1 after
  /// normalisation): adds (idepth * baseline_sigma / |t|)^2 to an observation's variance, so
  /// tiny baselines, whose pose error is a large share of the baseline, count for little.
  float baseline_sigma = 0.001f;
  /// Relative uncertainty of the tracked rotation keyframe -> frame: a rotation is known to
  /// this share of itself, which moves a match by the same share of the rotation's image
  /// motion; its component along the epipolar line enters the disparity variance
  /// (docs/math/depth_filter.md, "Error model").
  float rotation_sigma = 0.0f;
  /// Allowed change of the apparent pattern scale between keyframe and frame.
  float min_rescale = 0.7f;
  float max_rescale = 1.4f;
  /// Validity counter (LSD): start, gain per consistent observation, cap factor.
  float initial_validity = 20.0f;
  float validity_gain = 5.0f;
  /// Regularisation: neighbour validity sum below this deletes a pixel; above
  /// `fill_validity` an empty pixel is filled.
  float min_neighbour_validity = 24.0f;
  float fill_validity = 30.0f;
  /// Pixel budget of an update: an estimate whose standard deviation is below this fraction
  /// of its inverse depth has converged, and an update re-observes only one in
  /// `converged_recheck` of those (in turn, so each is still checked every few frames);
  /// 0 re-observes every estimate every update. Chosen on the 300-frame procedural and
  /// real-texture orbits, judged on the rendered suite and the real clips
  /// (docs/configuration.md, "Pixel budget of a depth update").
  float converged_relative_sigma = 0.02f;
  int converged_recheck = 4;
  /// Seed of the random initialisation.
  std::uint64_t seed = 1;

  /// Throws std::invalid_argument naming the bad field.
  void Check() const;
};

}  // namespace parallax
