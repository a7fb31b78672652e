#pragma once
// Options of the System (backend/system.hpp): the start, the keyframe rule, each stage's
// options and the real-time mode (docs/configuration.md).

#include <cstddef>

#include "backend/graph_backend.hpp"
#include "backend/keyframe_refinement.hpp"
#include "backend/loop_closer.hpp"
#include "backend/relocalizer.hpp"
#include "backend/two_view_bootstrap.hpp"
#include "backend/update_direction.hpp"
#include "core/frame_quality.hpp"
#include "core/image_pyramid.hpp"
#include "depth/depth_options.hpp"
#include "depth/parallax_moments.hpp"
#include "tracking/se3_tracker.hpp"
#include "tracking/tracking_reference.hpp"

namespace parallax {

/// How the first keyframe gets its depth (docs/configuration.md, "Choosing the initialisation").
enum class Initialization {
  /// Both at once: random depth tracks from the first frame while a two-view pair is sought;
  /// the pair either confirms the random start (it is kept) or replaces it.
  kAuto,
  kRandom,   ///< LSD-SLAM style random inverse depth refined by the first frames
  kTwoView,  ///< ORB + essential matrix between the first frame and a later one, then stereo
};

/// The real-time mode (docs/realtime.md): tracking on the caller's thread against the
/// published keyframe, depth updates, keyframes and the backend on a mapping thread.
struct RealtimeOptions {
  bool enabled = false;
  /// Tracked frames that may wait for the mapping thread; when more arrive, the oldest
  /// waiting one is skipped (the newest refines depth best).
  int max_pending_frames = 1;
  /// TBB concurrency of tracking (caller's thread) and of the mapping thread: the two-core
  /// budget is one each, so that neither oversubscribes the other.
  int tracking_threads = 1;
  int mapping_threads = 1;
  /// TBB concurrency of the mapping jobs the caller waits for (the start, frames lost
  /// live): tracking is idle meanwhile, so they may have both cores. (Under ThreadSanitizer
  /// every real-time arena is one thread wide: libtbb is not instrumented.)
  int waited_mapping_threads = 2;
  /// TBB concurrency of a requested keyframe's job: it runs while the caller tracks the next
  /// frames, and a second thread there takes time from live tracking on two cores.
  int keyframe_mapping_threads = 2;
  /// OpenCV's thread pool (ORB extraction on the mapping thread) is process-wide: a
  /// real-time System sets it to this when it starts.
  int opencv_threads = 1;
  /// A frame past the keyframe rule asks mapping for a new keyframe and tracking goes on
  /// against the current one; when the rule's distance is exceeded by this factor (or
  /// usage and consistency fall below the rule's thresholds divided by it) before the new
  /// keyframe exists, tracking waits for it (unthrottled input would otherwise outrun the
  /// map: measured 12.9% of path on a 300-frame orbit without the wait).
  double keyframe_wait_factor = 1.5;
  /// While a requested keyframe is pending, a frame first waits for it until its call has
  /// taken this long less the previous live frame's tracking time (ms; 0: never), then
  /// tracks against whichever keyframe is published. Spreads the wait for a keyframe over
  /// the frames after the request instead of one overdue frame (docs/realtime.md, "Pacing").
  double keyframe_pacing_ms = 8.0;
  /// A frame that asks for a keyframe becomes a bridge for the live tracker: the keyframe's
  /// tracking points moved into it (LiveBridge). Tracking reads it instead of waiting once a
  /// frame is overdue, until the keyframe exists, and waits only when it is past the rule
  /// (by keyframe_wait_factor) from the bridge's frame too. Off: chosen on a tuning set, it
  /// lost accuracy unthrottled on fast motion in the judging set (docs/realtime.md).
  bool bridge_keyframe_requests = false;
  /// ... only when the keyframe's depth has had at least this many updates: a mapping
  /// thread that falls behind (refining little between keyframes) is waited for, as without
  /// the bridge, rather than outrun.
  int bridge_min_keyframe_updates = 1;
  /// The snapshot carries the world poses of this many newest finished keyframes, so that
  /// the live state can follow keyframe changes it did not see (docs/realtime.md).
  int snapshot_keyframe_poses = 8;
  /// TBB concurrency of the backend thread, and its niceness (0-19): with two cores it
  /// shares them with tracking and mapping, which go first when it is positive.
  int backend_threads = 1;
  int backend_nice = 10;
  /// TBB concurrency of the backend's remaining work while a caller waits for it
  /// (FinishMapping at the end of a sequence, with tracking and mapping done).
  int backend_drain_threads = 2;
  /// Until the map is usable (the start, a new map after a long loss, the first
  /// relocalisation on a loaded map) a frame is
  /// handed to the mapping thread and answered at once without a pose (initialising; its
  /// pose comes with the map: poses revised). false: the caller waits until its own frame is
  /// mapped (its provisional pose comes back with the answer).
  bool answer_start_at_once = true;
  /// ... none of them is skipped; when this many wait for mapping (1 s of a 30 Hz camera) the
  /// caller waits too (a recording fed faster than the start maps). When the start is
  /// complete the caller waits once until mapping has done the queued frames, then tracks
  /// live from mapping's newest state.
  int max_queued_start_frames = 30;
  /// The catch-up after the start (docs/realtime.md): a queued frame with newer ones behind
  /// it refines depth only while the current keyframe has had fewer than this many updates
  /// (the start's keyframe has had initialization_updates; a keyframe made in the catch-up
  /// gets this many before later frames only track).
  int catch_up_refinements = 8;

  void Check() const;
};

struct SystemOptions {
  Initialization initialization = Initialization::kAuto;
  TwoViewBootstrapOptions bootstrap;
  /// Give up the two-view search after this many frames without a pair (two_view: then start
  /// from random depth at that frame; auto: keep the random start).
  int bootstrap_max_frames = 60;
  /// Auto: the random start agrees with a two-view pair when the rotations differ by less
  /// than this and the translation directions by less than `auto_max_direction_deg`.
  double auto_max_rotation_deg = 2.5;
  double auto_max_direction_deg = 60.0;
  /// Auto, when the geometry agrees: 0 keeps the pair's start (refined by the buffered
  /// frames); a value > 0 keeps it only if its mean residual over the buffered frames is
  /// below this fraction of the random start's (docs/configuration.md, "Choosing the
  /// initialisation": since the sub-pixel pair, 0.9 kept the worse start on most sequences
  /// where the two differ).
  double auto_pair_residual_ratio = 0.0;
  /// Auto, refining the pair's start with the buffered frames: every this-many-th frame,
  /// counted back from the newest (which always refines), is tracked and updates depth; the
  /// others keep the pose the pair's first tracking gave them until the start tracks them
  /// all again. 1: every frame (the default until 2026-12-06; docs/configuration.md,
  /// "Choosing the initialisation", has why 2 and on which sets it was chosen and judged).
  int pair_refine_stride = 2;
  /// The first keyframe needs at least this share of its pixels with enough gradient for
  /// depth (a dark or blank first frame is skipped and reported lost).
  double min_start_texture = 0.01;
  /// Auto and random: start again from the current frame after this many frames lost in a row
  /// before initialisation completed.
  int restart_after_lost = 10;
  /// ... and at once when a frame's brightness differs from the first keyframe's by more
  /// than this factor (tracking's gain estimate): the exposure is still settling, as after a
  /// very dark start, and the start keyframe would soon be beyond tracking's brightness
  /// range (docs/reliability.md, "Hard input").
  double max_start_exposure_change = 2.0;
  /// Frames without usable structure (blank, dark, blown out, noise) are reported lost
  /// before tracking: they would otherwise be "tracked" into a garbage pose.
  FrameQualityOptions quality;
  PyramidOptions pyramid;
  TrackingReferenceOptions reference;
  Se3TrackerOptions tracker;
  DepthFilterOptions depth;
  /// Translation direction of the depth updates' poses checked against the essential matrix.
  UpdateDirectionOptions update_direction;
  /// New keyframe when |t_kf_frame| * mean idepth (distance relative to the mean depth)
  /// exceeds this, or when fewer than `min_keyframe_usage` of the keyframe points are in view.
  double keyframe_distance = 0.15;
  /// The distance of that rule as the image sees it (ParallaxMoments::ImageDistance): a
  /// translation along the optical axis counts by how far it moves the keyframe's points,
  /// as DSO's translational-flow rule does (docs/math/keyframe_rule.md); false: |t| E[rho].
  bool keyframe_distance_in_image = true;
  /// ... or when the frame has turned more than this from the keyframe (degrees; 0: off).
  /// A rotation moves every point alike and is no distance for depth, but in a fast turn the
  /// view leaves the keyframe within a few frames (docs/math/keyframe_rule.md, "Turns").
  double keyframe_rotation_deg = 30.0;
  /// The turn bound counts only for a turn faster than this, degrees per frame on average
  /// over the keyframe's frames (0: any turn). A slow turn keeps the view for many frames and
  /// the usage rule ends the keyframe when it leaves; a fast one (a U-turn) leaves it before
  /// that rule can see it (docs/math/keyframe_rule.md, "Turns").
  double keyframe_rotation_min_rate_deg = 4.0;
  double min_keyframe_usage = 0.6;
  /// ... or when the share of consistent points falls below this (the view has changed
  /// enough that the keyframe explains it worse; DSO uses a residual-growth rule alike).
  double min_keyframe_good_ratio = 0.75;
  /// No depth update when the baseline relative to the mean depth is below this (static
  /// camera or pure rotation: no parallax, nothing to learn).
  double min_update_baseline = 0.004;
  /// When tracking against the current keyframe is lost, the last `recent_keyframes` finished
  /// keyframes are tried (from the pose propagated through the similarities, and from the
  /// keyframe's own pose); the first that re-acquires (FrameTracker::Reacquires) becomes the
  /// current keyframe again.
  int recent_keyframes = 4;
  /// Frames tracked into a keyframe before it may be replaced ...
  int min_frames_per_keyframe = 3;
  /// ... unless fewer than this share of its points is in view: a fast turn leaves a keyframe
  /// within two frames, and waiting for the third makes the next keyframe from a frame that
  /// saw little of it (docs/math/tracking.md, "A sudden turn"). 0 disables.
  double early_keyframe_usage = 0.3;
  /// The random start counts as initialised after this many depth updates of the first
  /// keyframe; the frames tracked before that are then tracked again against the converged
  /// depth and their poses revised (design.md section 3a). 20 (two thirds of a second at 30
  /// frames/s; 30 before) makes the start's one-off comparison a third cheaper: 90-frame
  /// renders 9-13% faster end to end, TUM 5.6 -> 5.9 mm, renders unchanged within noise.
  int initialization_updates = 20;
  /// When initialisation completes, the first keyframe's depth and the buffered frames'
  /// poses are refined jointly (docs/math/keyframe_refinement.md): the depth filter's
  /// alternation leaves a smooth distortion (a tilt) that joint refinement removes. Off by
  /// default, and ungated when on (max_point_relative_sigma 0): the information gate trades
  /// the hand-held renders' gain for the KITTI clip's (docs/benchmarks.md, "The start
  /// refinement's information gate").
  KeyframeRefinementOptions start_refinement;
  /// ... on at most this many of the buffered frames (spread, the last included); all are
  /// then tracked again against the refined depth.
  int start_refinement_frames = 10;
  /// When a keyframe is left, its depth and the poses of the frames that updated it are
  /// refined jointly, as at the start, and the refined depth is what the next keyframe
  /// inherits (the poses stay as tracked) (docs/math/keyframe_refinement.md, "Every keyframe"). Off
  /// by default: it costs about 0.2 s per keyframe at 640x480, and its effect is mixed on the
  /// judging renders (docs/benchmarks.md, "Refining every keyframe").
  KeyframeRefinementOptions keyframe_refinement;
  /// ... with at most this many of the window's frames (spread, the newest included) ...
  int keyframe_refinement_frames = 6;
  /// ... when at least this many frames updated the keyframe: short windows have too little
  /// baseline (refining them made the real clips, whose windows are 3-5 frames long, worse:
  /// docs/benchmarks.md, "Refining every keyframe").
  int keyframe_refinement_min_window = 9;
  /// Frames of the window held for it (each holds its pyramid, ~6 MB at 640x480); a longer
  /// window is thinned evenly (KeyframeWindow).
  int keyframe_window_capacity = 12;
  /// At most this many frames are kept for re-tracking before initialisation completes (a
  /// static start would otherwise keep them all); older ones keep their first pose.
  int max_buffered_frames = 60;
  /// ... and at most this many bytes of their pyramids (an 8000x6000 frame's pyramid is
  /// about 1 GB: a count alone does not bound memory).
  double max_buffered_megabytes = 512.0;
  /// Constraint search and pose-graph optimisation when a keyframe is finished; false keeps
  /// the tracking chain as it is (odometry edges only, never optimised).
  bool optimize_graph = true;
  /// trajectory.txt: the frames tracked towards a keyframe follow the graph's correction of
  /// it in part, growing along the way, instead of keeping their tracked pose relative to the
  /// keyframe they were tracked against up to the next one (backend/frame_trajectory.hpp).
  bool spread_keyframe_corrections = true;
  /// ... unless the keyframe's tracked step departs from the frames' motion by more than
  /// this times the step before it (FrameAnchors::max_step_change).
  double spread_max_step_change = 1.0;
  GraphBackendOptions backend;
  /// Place recognition and loop closure on finished keyframes (needs optimize_graph).
  LoopClosureOptions loop_closure;
  /// A frame lost against the current and recent keyframes is relocalised on the keyframe
  /// database (place recognition data is kept for it even without loop closure).
  RelocalizationOptions relocalization;
  /// Recovery from long loss: once no frame has had a pose for this long (input time,
  /// seconds) and relocalisation keeps failing, a new map is started at the next frame that
  /// can start one; a later loop to an earlier map merges the two.
  double new_map_after_lost_s = 2.0;
  RealtimeOptions realtime;

  void Check() const;

  /// The moments of `map` that the keyframe rule and the depth updates' baseline read: all
  /// of them with keyframe_distance_in_image, else only the mean inverse depth (the same
  /// value, to the bit, without the position-weighted sums nothing reads).
  ParallaxMoments KeyframeMoments(const InverseDepthMap& map) const;
  /// The keyframe rule's distance of a frame at `t_kf_frame` (keyframe coordinates) from a
  /// keyframe whose depth has moments `parallax` (see keyframe_distance_in_image).
  double KeyframeDistance(const ParallaxMoments& parallax, const Eigen::Vector3d& t_kf_frame) const;
  /// The keyframe rule (both modes): whether a frame tracked `frames_in_keyframe` frames
  /// into its keyframe, at `relative_distance` (KeyframeDistance) and `rotation_deg` (the
  /// angle of R_kf_frame, degrees), with tracking statistics `stats`, should become the next
  /// keyframe.
  bool WantsKeyframe(int frames_in_keyframe, double relative_distance, double rotation_deg,
                     const TrackingStats& stats) const;
  /// The rule's turn bound alone, the bound multiplied by `factor` (the real-time mode's
  /// overdue test): turned past it, faster than keyframe_rotation_min_rate_deg.
  bool TurnedPast(int frames_in_keyframe, double rotation_deg, double factor = 1.0) const;
  /// The angle of `T_kf_frame`'s rotation, degrees (the rule's `rotation_deg`).
  static double RotationDeg(const SE3d& T_kf_frame);
  /// Whether the pair's start is refined with buffered frame `index` of `buffered` (oldest
  /// first): every pair_refine_stride-th, counted back from the newest, which always is.
  bool PairRefinesWith(std::size_t index, std::size_t buffered) const;
};

}  // namespace parallax
