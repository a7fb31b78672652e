#pragma once
// What the System (backend/system.hpp) reports: per-frame results, events, revised and
// anchored poses, keyframe records and the run's real-time and keyframe-graph figures.

#include <cstdint>
#include <optional>
#include <vector>

#include "core/se3.hpp"
#include "core/sim3.hpp"
#include "tracking/tracking_result.hpp"

namespace parallax {

/// A corrected pose of an earlier frame; empty when the earlier pose is withdrawn (the frame
/// could not be tracked again, or initialisation restarted without it).
struct RevisedPose {
  std::int64_t frame_id = 0;
  double timestamp = 0.0;
  std::optional<SE3d> T_w_c;
  std::int64_t keyframe_id = -1;  ///< with T_kf_frame: the pose as the map stores it
  SE3d T_kf_frame;
};

/// Something that happened while processing a frame, for the CLI and the C API.
struct SystemEvent {
  enum class Kind {
    kKeyframeCreated,   ///< keyframe_id: the new current keyframe
    kKeyframeFinished,  ///< keyframe_id: frozen into the graph, constraints searched
    kGraphOptimised,    ///< every keyframe pose (and so every frame and point) may have moved
    kLost,              ///< the frame got no pose
    kRecovered,         ///< tracked again on a recent keyframe (keyframe_id)
    kPosesRevised,      ///< earlier frames' poses revised or withdrawn (initialisation)
    kRestarted,         ///< the start failed and began again at this frame
    kLoopClosed,        ///< keyframe_id closed a loop with loop_keyframe_id; graph optimised
    kRelocalised,       ///< lost beyond the recent keyframes, found again on keyframe_id
    kNewMap,            ///< lost too long: map_id started (keyframe_id: its first keyframe)
    kMapsMerged,        ///< a loop joined map_id into the map of loop_keyframe_id
    /// A stage's result diverged numerically (docs/reliability.md, "Divergence") and was
    /// dropped: keyframe_id is the keyframe it concerned, which stays as it was.
    kDiverged,
  };
  Kind kind = Kind::kLost;
  std::int64_t frame_id = 0;
  std::int64_t keyframe_id = -1;
  std::int64_t loop_keyframe_id = -1;  ///< kLoopClosed, kMapsMerged: the earlier keyframe
  int map_id = -1;                     ///< kNewMap: the new map; kMapsMerged: the merged one
};

/// A frame's pose as the map holds it: relative to a keyframe, so that a correction of the
/// keyframe graph moves the frame with it.
struct AnchoredPose {
  std::int64_t keyframe_id = 0;
  SE3d T_kf_frame;
};

/// A frame's world pose computed from the map (camera-to-world, first keyframe's world).
struct FramePose {
  std::int64_t frame_id = 0;
  double timestamp = 0.0;
  SE3d T_w_c;
};

/// Real-time mode figures (zero in the deterministic mode).
struct RealtimeStats {
  std::int64_t frames_tracked_live = 0;  ///< answered by the caller's tracker alone
  /// The caller waited for mapping to track the frame itself (start, lost, no keyframe).
  std::int64_t frames_mapped_waiting = 0;
  /// Answered at once without a pose before the map was initialised, mapped behind.
  std::int64_t frames_queued_for_start = 0;
  /// The caller waited for a keyframe it had asked for, then tracked the frame itself.
  std::int64_t frames_waiting_for_keyframe = 0;
  /// Frames that waited, within RealtimeOptions::keyframe_pacing_ms, for a pending keyframe.
  std::int64_t frames_paced_for_keyframe = 0;
  /// Tracked on the bridge at the frame that asked for a keyframe, while mapping made it.
  std::int64_t frames_tracked_on_bridge = 0;
  /// Tracked, never used to refine depth: refinements mapping skipped when behind, and start
  /// frames tracked in the catch-up after the start (docs/realtime.md).
  std::int64_t frames_skipped_by_mapping = 0;
};

/// Keyframe-graph figures for stats.json.
struct BackendStats {
  int optimisations = 0;
  int iterations = 0;
  int alignments = 0;
  int edges_rejected = 0;
  std::vector<double> optimisation_ms;
  int loop_candidates = 0;  ///< database candidates above the score gates
  int loop_checks = 0;      ///< consistent candidates verified geometrically
  int loops_rejected = 0;   ///< of them, failed verification
  int loops_closed = 0;
  std::vector<double> loop_ms;      ///< place recognition per finished keyframe
  int relocalisation_attempts = 0;  ///< frames lost beyond the recent keyframes
  int relocalisations = 0;
  int maps_started = 0;  ///< new maps after long loss (the first map not counted)
  int merges = 0;
  /// Numerical divergence caught at stage boundaries (docs/reliability.md, "Divergence"):
  /// frames whose tracking diverged (reported lost), depth estimates removed as non-finite or
  /// non-positive, keyframes not made because the propagated map diverged, keyframes whose backend
  /// step diverged (their chain edge kept).
  int frames_diverged = 0;
  int depth_estimates_diverged = 0;
  int keyframes_diverged = 0;
  int backend_steps_diverged = 0;

  /// Adds `other`'s counts and appends its timings.
  void Add(const BackendStats& other);
};

/// Per-frame outcome.
struct FrameResult {
  TrackingStatus status = TrackingStatus::kLost;
  /// Camera-to-world pose (world = first keyframe, its scale) as estimated now; empty when
  /// lost. The map keeps it as `anchor`, which later graph corrections move.
  std::optional<SE3d> T_w_c;
  std::optional<AnchoredPose> anchor;
  bool is_keyframe = false;
  /// The map had no initialised keyframe yet when the frame was posed (its pose is
  /// provisional: the start may revise or withdraw it).
  bool initialising = false;
  /// Answered before it was mapped (the real-time start, RealtimeOptions::
  /// answer_start_at_once): no pose yet and not lost; its pose, if the start gives it one,
  /// comes with the map (kPosesRevised, System::Trajectory).
  bool answered_before_mapping = false;
  TrackingStats stats;
  double tracking_ms = 0.0;  ///< wall time of tracking this frame
  double mapping_ms = 0.0;   ///< depth update and keyframe creation
  /// Earlier frames re-tracked (or withdrawn) when initialisation completed or restarted.
  std::vector<RevisedPose> revised;
  std::vector<SystemEvent> events;
};

/// A finished or current keyframe as the outputs need it.
struct KeyframeRecord {
  std::int64_t frame_id = 0;
  double timestamp = 0.0;
  Sim3d S_w_kf;    ///< keyframe-to-world similarity (scale: the keyframe's normalised depth)
  int map_id = 0;  ///< the map (world frame) it belongs to
};

}  // namespace parallax
