#pragma once
// Real-time mode, the caller's side (docs/realtime.md): the snapshot the mapping thread
// publishes after every frame it maps, and the live tracker that reads it.

#include <tbb/task_arena.h>

#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <utility>
#include <vector>

#include "backend/frame_tracker.hpp"
#include "core/sim3.hpp"
#include "depth/parallax_moments.hpp"
#include "tracking/tracking_reference.hpp"

namespace parallax {

/// What the mapping thread publishes for the live tracker after every frame it maps.
struct LiveSnapshot {
  bool usable = false;       ///< a current keyframe with depth to track against
  bool initialised = false;  ///< ... and the start is complete (keyframes may be made)
  std::int64_t keyframe_id = -1;
  std::shared_ptr<const TrackingReference> reference;
  Sim3d S_w_kf;
  MotionState motion;  ///< the mapping thread's tracker after its last frame
  /// The keyframe before the current one and its pose in the current one, taken together
  /// with S_w_kf (an optimisation between two snapshots moves both).
  std::int64_t previous_keyframe_id = -1;
  Sim3d S_kf_previous;
  /// World poses of the newest finished keyframes (taken with S_w_kf), so that the live
  /// state can follow over several keyframe changes it did not see.
  std::vector<std::pair<std::int64_t, Sim3d>> recent_poses;
  /// Of the current keyframe's depth (the keyframe rule's distance).
  ParallaxMoments parallax{1.0, 1.0, 0.0, 0.0, 0.0};
  std::uint64_t generation = 0;  ///< System::map_generation_
  /// Stereo updates the current keyframe's depth has had (InverseDepthMap::updates).
  std::uint32_t keyframe_updates = 0;
};

/// A reference at the frame that asked for a keyframe: the keyframe's tracking points moved
/// into it (TrackingReference::MovedTo). Tracking reads it until the mapping thread has made
/// and published that keyframe, instead of waiting for it (docs/realtime.md, "The bridge").
struct LiveBridge {
  std::int64_t keyframe_id = -1;  ///< the keyframe its depth was moved from
  std::uint64_t generation = 0;   ///< ... and that keyframe's map generation
  std::int64_t frame_id = -1;     ///< the frame it stands at
  SE3d T_kf_bridge;               ///< that frame's pose in the keyframe
  AffineBrightness affine;        ///< that frame's brightness relative to the keyframe
  std::shared_ptr<const TrackingReference> reference;
  /// A frame was overdue on the keyframe: tracking reads the bridge until the keyframe
  /// exists (before that, the keyframe itself).
  bool engaged = false;

  /// Whether it was moved from the snapshot's keyframe (and map generation).
  bool Serves(const LiveSnapshot& s) const {
    return reference && keyframe_id == s.keyframe_id && generation == s.generation;
  }
  /// A motion state in the keyframe re-expressed at the bridge's frame, and back (a rigid
  /// change of reference; brightness relative to the bridge's frame: I_frame = e^a' I_bridge
  /// + b' with a' = a - a_bridge, b' = b - e^a' b_bridge).
  MotionState ToBridge(MotionState m) const;
  MotionState FromBridge(MotionState m) const;
  /// A tracking result on the bridge re-expressed in the keyframe.
  TrackingResult FromBridge(TrackingResult t) const;
};

/// The caller's side: its own motion state, TBB arena and counters, and the snapshot.
struct LiveTracker {
  LiveTracker(const Se3TrackerOptions& options, int threads) : tracker(options), arena(threads) {}

  FrameTracker tracker;
  tbb::task_arena arena;
  std::int64_t keyframe_id = -1;                ///< the keyframe `tracker`'s state is in
  bool followed_initialised = false;            ///< the state adopted came from an initialised map
  std::int64_t keyframe_requested_in = -1;      ///< a frame asked for a keyframe after this one
  std::int64_t keyframe_request_frame = -1;     ///< ... that frame's id
  std::int64_t keyframe_request_sequence = -1;  ///< ... and its place in `tracked_live`
  std::int64_t waited_for_keyframe = 0;         ///< frames that waited for a requested keyframe
  std::int64_t paced_for_keyframe = 0;          ///< ... within the pacing budget
  double last_tracking_ms = 0.0;                ///< the previous live frame's tracking time
  std::int64_t tracked_live = 0;                ///< frames answered from live tracking, in order
  bool previous_lost = false;                   ///< the caller's previous frame got no pose
  std::int64_t mapped_waiting = 0;
  std::int64_t queued_for_start = 0;  ///< answered at once, mapped later (the start)
  /// The newest start frame queued for mapping and not yet caught up with (-1: none).
  std::int64_t last_queued_start = -1;
  /// Start frames the mapping thread tracked in the catch-up without refining depth.
  std::atomic<std::int64_t> caught_up{0};
  /// The mapping thread's: the keyframe of its last snapshot, and the one before it.
  std::int64_t published_keyframe_id = -1;
  std::int64_t published_previous_id = -1;
  std::int64_t tracked_on_bridge = 0;  ///< frames tracked on a LiveBridge
  std::mutex mutex;                    ///< guards `snapshot` (written by the mapping thread)
  LiveSnapshot snapshot;
  /// The bridge of the keyframe request pending (the caller's own; empty: none).
  std::optional<LiveBridge> bridge;

  LiveSnapshot Latest();
  /// The state continues in the published keyframe: a new keyframe re-expresses the last
  /// pose and velocity through the keyframes' similarity (velocity in the new depth unit);
  /// following the keyframe made at keyframe_request_frame, the rule's frame count includes
  /// the frames tracked live since that frame.
  void Follow(const LiveSnapshot& s);
  /// After the mapping thread tracked a frame itself, its state is the newest.
  void Adopt(const LiveSnapshot& s);
};

}  // namespace parallax
