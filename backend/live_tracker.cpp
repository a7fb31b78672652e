#include "backend/live_tracker.hpp"

#include <algorithm>
#include <cmath>
#include <optional>

namespace parallax {

LiveSnapshot LiveTracker::Latest() {
  const std::lock_guard<std::mutex> lock(mutex);
  return snapshot;
}

namespace {

// Brightness relative to a reference whose own brightness is `r` (see LiveBridge), and back.
AffineBrightness RelativeTo(const AffineBrightness& x, const AffineBrightness& r) {
  const float a = x.a - r.a;
  return AffineBrightness{a, x.b - std::exp(a) * r.b};
}

AffineBrightness Compose(const AffineBrightness& x, const AffineBrightness& r) {
  return AffineBrightness{x.a + r.a, x.b + std::exp(x.a) * r.b};
}

}  // namespace

MotionState LiveBridge::ToBridge(MotionState m) const {
  m.T_kf_last = T_kf_bridge.Inverse() * m.T_kf_last;
  m.affine = RelativeTo(m.affine, affine);
  return m;
}

MotionState LiveBridge::FromBridge(MotionState m) const {
  m.T_kf_last = T_kf_bridge * m.T_kf_last;
  m.affine = Compose(m.affine, affine);
  return m;
}

TrackingResult LiveBridge::FromBridge(TrackingResult t) const {
  t.T_kf_frame = T_kf_bridge * t.T_kf_frame;
  t.affine = Compose(t.affine, affine);
  return t;
}

void LiveTracker::Follow(const LiveSnapshot& s) {
  // During the start the map may be replaced under the same keyframe id (a two-view pair
  // replacing the random start rescales it; a restart): the mapping thread's state, which
  // is at most a frame or two behind then, is the one to continue from.
  if (!s.initialised || !followed_initialised) {
    tracker.SetState(s.motion);
    keyframe_id = s.keyframe_id;
    followed_initialised = s.initialised;
    return;
  }
  if (s.keyframe_id == keyframe_id) return;
  // The live state's keyframe in the new one: directly, or through the world poses of
  // the newest keyframes; otherwise the mapping thread's (older) state.
  std::optional<Sim3d> S_new_old;
  if (keyframe_id >= 0 && keyframe_id == s.previous_keyframe_id) S_new_old = s.S_kf_previous;
  for (const auto& [id, S_w_old] : s.recent_poses) {
    if (!S_new_old && id == keyframe_id) S_new_old = s.S_w_kf.Inverse() * S_w_old;
  }
  if (!S_new_old) {
    tracker.SetState(s.motion);
  } else {
    MotionState m = tracker.State();
    m.T_kf_last = (*S_new_old * Sim3d(m.T_kf_last)).RigidPart();
    m.T_prev_last =
        SE3d(m.T_prev_last.Rotation(), m.T_prev_last.Translation() * S_new_old->Scale());
    m.frames_in_keyframe = s.motion.frames_in_keyframe;
    tracker.SetState(m);
  }
  if (s.keyframe_id == keyframe_request_frame && keyframe_request_sequence >= 0) {
    // The keyframe this caller asked for: the keyframe rule counts the frames tracked live
    // since the frame that asked, which the mapping thread made the keyframe without seeing
    // (on a bridge, many).
    MotionState m = tracker.State();
    m.frames_in_keyframe = std::max(m.frames_in_keyframe,
                                    static_cast<int>(tracked_live - keyframe_request_sequence - 1));
    tracker.SetState(m);
  }
  keyframe_id = s.keyframe_id;
}
void LiveTracker::Adopt(const LiveSnapshot& s) {
  tracker.SetState(s.motion);
  keyframe_id = s.usable ? s.keyframe_id : -1;
  followed_initialised = s.initialised;
}

}  // namespace parallax
