#include "backend/frame_tracker.hpp"

#include <string>

namespace parallax {

FrameTracker::FrameTracker(const Se3TrackerOptions& options)
    : tracker_(options), velocity_rescale_ratio_(options.velocity_rescale_ratio) {}

TrackingResult DivergedTracking(const std::exception& divergence) {
  TrackingResult result;  // lost
  result.stats.diverged = true;
  result.stats.reason = std::string("tracking diverged: ") + divergence.what();
  return result;
}

SE3d FrameTracker::VelocityOver(double gap) const {
  if (!(gap > 0.0) || !(state_.velocity_interval > 0.0)) return state_.T_prev_last;
  const double ratio = gap / state_.velocity_interval;
  if (ratio <= velocity_rescale_ratio_ && ratio * velocity_rescale_ratio_ >= 1.0) {
    return state_.T_prev_last;  // frame-rate jitter: the velocity as measured
  }
  return SE3d::Exp(ratio * state_.T_prev_last.Log());
}

SE3d FrameTracker::Predicted(double timestamp) const {
  return state_.T_kf_last * VelocityOver(timestamp - state_.last_timestamp);
}

TrackingResult FrameTracker::Track(const TrackingReference& reference, const Frame& frame) {
  const double gap = frame.Timestamp() - state_.last_timestamp;  // NaN after no frame
  TrackingResult tracked = tracker_.Track(
      reference, frame, MotionHypotheses(state_.T_kf_last, VelocityOver(gap)), state_.affine);
  // The last frame's residual is a bar for the next frame, not for one after frames that
  // never reached the tracker (dropped at a camera's rate, skipped, unusable): the view has
  // moved on meanwhile. Frames lost here are no such gap.
  const bool after_gap = state_.velocity_interval > 0.0 &&
                         gap > velocity_rescale_ratio_ * state_.velocity_interval &&
                         !lost_since_state_;
  if (!after_gap && tracked.status != TrackingStatus::kLost && !AgreesWithHistory(tracked)) {
    tracked.status = TrackingStatus::kLost;
    tracked.stats.reason = "residual far above the last tracked frame's";
  }
  if (tracked.status == TrackingStatus::kLost) {
    lost_since_state_ = true;
    return tracked;
  }
  lost_since_state_ = false;
  state_.residual_rms = tracked.stats.residual_rms;
  state_.velocity_interval = gap > 0.0 ? gap : 0.0;
  state_.last_timestamp = frame.Timestamp();
  state_.T_prev_last = state_.T_kf_last.Inverse() * tracked.T_kf_frame;
  state_.T_kf_last = tracked.T_kf_frame;
  state_.affine = tracked.affine;
  ++state_.frames_in_keyframe;
  return tracked;
}

TrackingResult FrameTracker::TrackFrom(const TrackingReference& reference, const Frame& frame,
                                       const SE3d& guess, const AffineBrightness& affine) {
  return tracker_.Track(reference, frame, {guess}, affine);
}

TrackingResult FrameTracker::Retrack(const TrackingReference& reference, const Frame& frame,
                                     const SE3d& guess, const AffineBrightness& affine) {
  return tracker_.Refine(reference, frame, guess, affine);
}

bool FrameTracker::AgreesWithHistory(const TrackingResult& result) const {
  const double jump = tracker_.Options().max_residual_jump;
  // Right after a loss a confident result is held to the bar as well: it has no motion
  // behind it (a textureless wall: confident at 6x the residual, 45 degrees off).
  return jump <= 0.0 || !(state_.residual_rms > 0.0) ||
         (tracker_.Confident(result) && !lost_since_state_) ||
         result.stats.residual_rms <= jump * state_.residual_rms;
}

bool FrameTracker::Reacquires(const TrackingResult& result) const {
  return tracker_.Confident(result) &&
         result.stats.points_good >= tracker_.Options().min_reacquisition_points;
}

std::optional<std::pair<std::size_t, TrackingResult>> FrameTracker::Recover(
    const std::vector<RecoveryCandidate>& candidates, const Frame& frame, const Sim3d& S_w_last) {
  for (std::size_t k = 0; k < candidates.size(); ++k) {
    const RecoveryCandidate& c = candidates[k];
    // Two starts, each tracked on its own (the tracker would prefer a start that sees few
    // points with small residuals): the last pose carried over through the similarities,
    // and the keyframe's own pose (the camera came back to where it was taken).
    TrackingResult r = tracker_.Track(
        *c.reference, frame, {(c.S_w_kf.Inverse() * S_w_last).RigidPart()}, AffineBrightness{});
    if (!Reacquires(r)) {
      r = tracker_.Track(*c.reference, frame, {SE3d()}, AffineBrightness{});
    }
    if (!Reacquires(r)) continue;
    state_ = MotionState{r.T_kf_frame, SE3d(), r.affine, 1, frame.Timestamp(), 0.0};
    state_.residual_rms = r.stats.residual_rms;
    lost_since_state_ = false;
    return std::make_pair(k, std::move(r));
  }
  return std::nullopt;
}

void FrameTracker::StartKeyframe() {
  // The brightness estimate carries over: the same camera sees the same scene.
  state_ = MotionState{
      SE3d(), SE3d(), state_.affine, 0, state_.last_timestamp, 0.0, state_.residual_rms};
}

}  // namespace parallax
