#pragma once
// The tracking stage: a frame against the current keyframe's published reference, with the
// constant-velocity motion hypotheses; recovery on recent keyframes. Never touches depth.

#include <cstddef>
#include <exception>
#include <limits>
#include <optional>
#include <utility>
#include <vector>

#include "core/frame.hpp"
#include "core/se3.hpp"
#include "core/sim3.hpp"
#include "tracking/se3_tracker.hpp"
#include "tracking/tracking_reference.hpp"

namespace parallax {

/// What the tracker carries from frame to frame within one keyframe.
struct MotionState {
  SE3d T_kf_last;    ///< pose of the last tracked frame in the keyframe
  SE3d T_prev_last;  ///< last inter-frame motion (for the constant-velocity guess)
  AffineBrightness affine;
  int frames_in_keyframe = 0;
  /// Input time of the last tracked frame (seconds; NaN: unknown) and the time T_prev_last
  /// spans (0: unknown), so that the guess can follow the time a gap of frames took.
  double last_timestamp = std::numeric_limits<double>::quiet_NaN();
  double velocity_interval = 0.0;
  /// Residual rms of the last tracked frame, grey levels (0: unknown).
  double residual_rms = 0.0;
};

/// A keyframe to try when tracking is lost on the current one.
struct RecoveryCandidate {
  const TrackingReference* reference = nullptr;
  Sim3d S_w_kf;
};

/// The result a tracking call reports when it threw NumericalDivergence: lost, `diverged`,
/// the reason naming the divergence (docs/reliability.md, "Divergence").
TrackingResult DivergedTracking(const std::exception& divergence);

class FrameTracker {
 public:
  explicit FrameTracker(const Se3TrackerOptions& options);

  /// Tracks `frame` on `reference` from the motion hypotheses; a frame that is not lost
  /// advances the motion state (a lost one keeps the last good state). The velocity is
  /// rescaled to the frame's time gap beyond `velocity_rescale_ratio` (Se3TrackerOptions).
  TrackingResult Track(const TrackingReference& reference, const Frame& frame);
  /// Whether a result tracked with the motion model agrees with the frames before it: one
  /// with a residual above `max_residual_jump` times the last tracked frame's does not unless
  /// it is confident (Se3Tracker::Confident) and Track lost no frame since that one; Track
  /// reports it lost (docs/math/tracking.md, "A residual far above the last frame's"), except
  /// after a gap of frames that never reached it (dropped, skipped, unusable).
  bool AgreesWithHistory(const TrackingResult& result) const;
  /// One start, no state change (frames tracked again during initialisation).
  TrackingResult TrackFrom(const TrackingReference& reference, const Frame& frame,
                           const SE3d& guess, const AffineBrightness& affine);
  /// A frame tracked before, again on a refined map from its pose then (Se3Tracker::Refine);
  /// no state change.
  TrackingResult Retrack(const TrackingReference& reference, const Frame& frame, const SE3d& guess,
                         const AffineBrightness& affine);
  /// Tries the candidates in order, each from the last pose carried over through the
  /// similarities (S_w_last: the last tracked frame's world similarity) and then from the
  /// keyframe's own pose; the first that re-acquires (Reacquires) restarts the motion state
  /// on it.
  std::optional<std::pair<std::size_t, TrackingResult>> Recover(
      const std::vector<RecoveryCandidate>& candidates, const Frame& frame, const Sim3d& S_w_last);

  /// Whether a result may re-acquire tracking after a loss: "ok" and not suspect (at least
  /// `suspect_good_ratio` consistent), with at least `min_reacquisition_points` consistent
  /// points. With no motion to support it, a result that would be searched again, or a few
  /// hundred points of a weakly textured view, is not evidence enough (docs/math/tracking.md,
  /// "Re-acquisition").
  bool Reacquires(const TrackingResult& result) const;

  /// The motion model's guess of a frame at `timestamp`: the last pose moved on by the
  /// velocity over the time since it (T_kf_frame).
  SE3d Predicted(double timestamp) const;
  /// A new keyframe: pose and velocity restart at identity, no frame tracked in it yet.
  void StartKeyframe();
  const MotionState& State() const { return state_; }
  void SetState(const MotionState& state) { state_ = state; }

 private:
  /// The constant velocity over `gap` seconds since the last tracked frame.
  SE3d VelocityOver(double gap) const;

  Se3Tracker tracker_;
  double velocity_rescale_ratio_;
  bool lost_since_state_ = false;  ///< Track lost a frame since the state's last tracked one
  MotionState state_;
};

}  // namespace parallax
