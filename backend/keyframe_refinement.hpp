#pragma once
// Joint photometric refinement of one keyframe's inverse depths and the poses of the frames
// that observed it: a small bundle adjustment over the keyframe's window
// (docs/math/keyframe_refinement.md).

#include <cstddef>
#include <cstdint>
#include <vector>

#include "core/frame.hpp"
#include "core/se3.hpp"

namespace parallax {

struct KeyframeRefinementOptions {
  /// Off by default (docs/benchmarks.md, "Start refinement" and "The start refinement's
  /// information gate").
  bool enabled = false;
  /// Pyramid levels, coarse to fine: coarsest_level .. 0.
  int coarsest_level = 1;
  /// Levenberg-Marquardt iterations of the joint problem per level.
  int joint_iterations = 10;
  /// Points in the joint (poses + inverse depths) problem, taken evenly from the keyframe's
  /// estimates; every estimate is then refined alone against the refined poses.
  int max_joint_points = 3000;
  /// Gauss-Newton iterations of each point alone, per level (steps limited like the joint
  /// ones).
  int point_iterations = 3;
  /// Frames each point is refined on (spread over the window, the widest baseline first).
  int point_frames = 8;
  /// Grey-level noise (sigma) and the Huber threshold in sigmas.
  float pixel_noise_sigma = 4.0f;
  float huber_k = 1.5f;
  /// A point needs this many frames it projects into to be refined.
  int min_observations = 3;
  /// A point's inverse depth may change by at most this share; beyond, it keeps its value
  /// (a different minimum, not a correction).
  float max_relative_change = 0.25f;
  /// A point is refined alone only when the frames determine it: the standard deviation its
  /// photometric information implies at pixel noise, at its starting value on level 0, is at
  /// most this share of its inverse depth. Points the frames see without parallax, or with
  /// their gradient across the epipolar lines, keep their value. 0 disables the gate.
  float max_point_relative_sigma = 0.0f;
  double initial_lambda = 1e-2;
  /// A point's inverse depth moves at most this far per step, in pixels of its largest image
  /// motion (the photometric linearisation holds within about a pixel).
  double max_pixel_step = 1.0;

  /// Throws std::invalid_argument naming the bad field.
  void Check() const;
};

/// A frame that observed the keyframe: its pose (keyframe from frame, keyframe units) and the
/// brightness mapping I_frame ~ gain * I_keyframe + offset that tracking found.
struct RefinementFrame {
  const Frame* frame = nullptr;
  SE3d T_kf_frame;
  float gain = 1.0f;
  float offset = 0.0f;
};

struct KeyframeRefinementResult {
  std::vector<SE3d> T_kf_frame;  ///< per input frame
  std::vector<float> idepth;     ///< per input point (unchanged where not refined)
  int points_refined = 0;
  int joint_points = 0;
  double initial_cost = 0.0;  ///< Huber cost of the joint problem at level 0, before
  double final_cost = 0.0;    ///< ... and after
  int iterations = 0;         ///< accepted joint steps over all levels
};

/// Indices of at most `count` of `n` items spread evenly over them, oldest first, the first
/// and the newest (n - 1, the widest baseline) always included: how the refinements choose
/// frames from a window. Empty when n == 0.
std::vector<std::size_t> SpreadIndices(std::size_t n, std::size_t count);

/// Refines `idepth` (inverse depths, keyframe units, of the level-0 pixels `pixel` =
/// y * width + x) and the frames' poses by minimising the Huber photometric error of every
/// point in every frame, coarse to fine. The keyframe is the gauge; the scale is kept by
/// holding the mean inverse depth of the joint points. Deterministic.
KeyframeRefinementResult RefineKeyframe(const Frame& keyframe,
                                        const std::vector<std::int32_t>& pixel,
                                        const std::vector<float>& idepth,
                                        const std::vector<RefinementFrame>& frames,
                                        const KeyframeRefinementOptions& options);

}  // namespace parallax
