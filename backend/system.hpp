#pragma once
// The visual-odometry pipeline (deterministic mode): tracking against the current keyframe,
// depth updates, keyframe creation with propagation and scale normalisation.

#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <shared_mutex>
#include <span>
#include <string>
#include <vector>

#include "backend/frame_tracker.hpp"
#include "backend/graph_backend.hpp"
#include "backend/keyframe_graph.hpp"
#include "backend/keyframe_refinement.hpp"
#include "backend/loop_closer.hpp"
#include "backend/mapper.hpp"
#include "backend/place_recognizer.hpp"
#include "backend/relocalizer.hpp"
#include "backend/two_view_bootstrap.hpp"
#include "backend/update_direction.hpp"
#include "core/frame.hpp"
#include "core/frame_quality.hpp"
#include "core/image.hpp"
#include "core/pinhole_camera.hpp"
#include "core/sim3.hpp"
#include "core/validity_mask.hpp"
#include "depth/depth_filter.hpp"
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
  /// OpenCV's thread pool (ORB extraction on the mapping thread) is process-wide: a
  /// real-time System sets it to this when it starts.
  int opencv_threads = 1;
  /// A frame past the keyframe rule asks mapping for a new keyframe and tracking goes on
  /// against the current one; when the rule's distance is exceeded by this factor (or
  /// usage and consistency fall below the rule's thresholds divided by it) before the new
  /// keyframe exists, tracking waits for it (unthrottled input would otherwise outrun the
  /// map: measured 12.9% of path on a 300-frame orbit without the wait).
  double keyframe_wait_factor = 1.5;
  /// The snapshot carries the world poses of this many newest finished keyframes, so that
  /// the live state can follow keyframe changes it did not see (docs/realtime.md).
  int snapshot_keyframe_poses = 8;
  /// TBB concurrency of the backend thread, and its niceness (0-19): with two cores it
  /// shares them with tracking and mapping, which go first when it is positive.
  int backend_threads = 1;
  int backend_nice = 10;

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
  /// Auto, when the geometry agrees: the pair's start replaces the random one only if its
  /// mean residual over the buffered frames is below this fraction of the random start's
  /// (measured ratios: 0.61-0.71 where the pair is right, 1.04-1.56 where random is).
  double auto_pair_residual_ratio = 0.9;
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
  double min_keyframe_usage = 0.6;
  /// ... or when the share of consistent points falls below this (the view has changed
  /// enough that the keyframe explains it worse; DSO uses a residual-growth rule alike).
  double min_keyframe_good_ratio = 0.75;
  /// No depth update when the baseline relative to the mean depth is below this (static
  /// camera or pure rotation: no parallax, nothing to learn).
  double min_update_baseline = 0.004;
  /// When tracking against the current keyframe is lost, the last `recent_keyframes` finished
  /// keyframes are tried (from the pose propagated through the similarities, and from the
  /// keyframe's own pose); the first that tracks "ok" becomes the current keyframe again.
  int recent_keyframes = 4;
  /// Frames tracked into a keyframe before it may be replaced.
  int min_frames_per_keyframe = 3;
  /// The random start counts as initialised after this many depth updates of the first
  /// keyframe; the frames tracked before that are then tracked again against the converged
  /// depth and their poses revised (design.md section 3a). 20 (two thirds of a second at 30
  /// frames/s; 30 before) makes the start's one-off comparison a third cheaper: 90-frame
  /// renders 9-13% faster end to end, TUM 5.6 -> 5.9 mm, renders unchanged within noise.
  int initialization_updates = 20;
  /// When initialisation completes, the first keyframe's depth and the buffered frames'
  /// poses are refined jointly (docs/math/keyframe_refinement.md): the depth filter's
  /// alternation leaves a smooth distortion (a tilt) that joint refinement removes.
  KeyframeRefinementOptions start_refinement;
  /// ... on at most this many of the buffered frames (spread, the last included); all are
  /// then tracked again against the refined depth.
  int start_refinement_frames = 10;
  /// At most this many frames are kept for re-tracking before initialisation completes (a
  /// static start would otherwise keep them all); older ones keep their first pose.
  int max_buffered_frames = 60;
  /// ... and at most this many bytes of their pyramids (an 8000x6000 frame's pyramid is
  /// about 1 GB: a count alone does not bound memory).
  double max_buffered_megabytes = 512.0;
  /// Constraint search and pose-graph optimisation when a keyframe is finished; false keeps
  /// the tracking chain as it is (odometry edges only, never optimised).
  bool optimize_graph = true;
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
};

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
  /// The caller waited for a keyframe it had asked for, then tracked the frame itself.
  std::int64_t frames_waiting_for_keyframe = 0;
  std::int64_t frames_skipped_by_mapping = 0;  ///< tracked, never used to refine depth
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

struct MappingJob;
struct LiveTracking;
struct LiveSnapshot;
class MappingWorker;
class BackendWorker;
struct LiveTracker;

/// Runs tracking and mapping for each frame. Deterministic mode: every stage in order on the
/// caller's thread (bit-identical results). Real-time mode (options.realtime): tracking on
/// the caller's thread, mapping and the backend on a thread the System owns
/// (docs/realtime.md). A System is used from one thread at a time; its queries are safe
/// while its mapping thread runs, except Graph(), which needs FinishMapping() first.
class System {
 public:
  /// `camera` is the ideal pinhole camera of the (already undistorted) images.
  explicit System(const PinholeCamera& camera, const SystemOptions& options = {});
  /// Stops the mapping thread (waiting frames are dropped, the running one finishes).
  ~System();
  System(const System&) = delete;
  System& operator=(const System&) = delete;

  /// Processes one undistorted 8-bit image. Throws std::invalid_argument for a wrong size,
  /// before anything changes. Real-time mode: returns once the frame is tracked (waiting for
  /// mapping only at the start, when lost, or when a new keyframe must exist first); events
  /// of the mapping thread come with the next result; an exception the mapping thread threw
  /// is rethrown here.
  FrameResult ProcessFrame(const ImageU8& image, double timestamp);
  /// The end of the input. Real-time mode: first waits until every frame handed to mapping
  /// is mapped and the backend is idle. Both modes: then the current keyframe goes through
  /// the backend as a finished one would (constraint search, place recognition, loop
  /// closure), so that a sequence ending where it began can close its loop; it stays the
  /// current keyframe, and frames given later continue on it. Returns the events no frame
  /// has reported yet. Graph() and the outputs are final afterwards.
  std::vector<SystemEvent> FinishMapping();
  /// Real-time mode: drops the frames waiting for mapping, lets the running one finish and
  /// stops the thread (keyframes already made are kept; later frames are refused).
  void StopMapping();
  RealtimeStats Realtime() const;

  /// Every keyframe (finished ones through the optimised graph, then the current one).
  std::vector<KeyframeRecord> Keyframes() const;
  /// Semi-dense points of all keyframes (world coordinates), confirmed estimates only,
  /// through the keyframes' current (optimised) poses.
  std::vector<Eigen::Vector3f> MapPoints() const;
  /// The same points one at a time, with their grey level (for writing large maps without
  /// copying them).
  void ForEachMapPoint(const std::function<void(const MapPoint&)>& fn) const;
  /// Every frame that has a pose, in frame order, through its keyframe's current pose.
  std::vector<FramePose> Trajectory() const;

  /// Writes the map (every keyframe, the unfinished current one included, with its depth,
  /// pose, edges and ORB features) to `path` atomically (docs/map_files.md). Changes nothing
  /// in the system. Throws std::logic_error before the first keyframe is initialised and
  /// MapFileError when the file cannot be written.
  void SaveMap(const std::string& path) const;
  /// The map file's bytes (as SaveMap writes them).
  std::vector<std::uint8_t> EncodeMapBytes() const;
  /// Loads a map into a system that has not processed a frame yet: the next frames are
  /// relocalised on it and, once one is found, tracked and mapped in its world frame (a new
  /// map is started after `new_map_after_lost_s` without relocalisation). Frame ids continue
  /// after the saved ones. Throws std::logic_error when frames were processed and
  /// MapFileError for an unreadable, corrupt or foreign file (the camera must be the same);
  /// on a throw the system is unchanged.
  void LoadMap(const std::string& path);
  void LoadMapBytes(std::span<const std::uint8_t> bytes, const std::string& source);
  /// True while the current map has no initialised keyframe yet (the start, or a new map
  /// after a long loss); frames may have provisional poses.
  bool Initialising() const;
  /// True while a loaded map waits for the first relocalisation.
  bool AwaitingRelocalisation() const;
  const KeyframeGraph& Graph() const { return graph_; }
  /// The map new keyframes currently join (0 until a long loss started another).
  int CurrentMap() const;
  BackendStats Backend() const;
  /// Memory held by place recognition (keyframe features and vectors).
  std::size_t PlaceRecognitionBytes() const;
  /// The id the next frame will get (ids continue after a loaded map's).
  std::int64_t NextFrameId() const { return frame_count_; }
  int FramesProcessed() const { return static_cast<int>(frame_count_ - first_frame_id_); }
  /// Frames rejected by the quality gate (SystemOptions::quality).
  int FramesUnusable() const { return frames_unusable_; }
  /// Index of the frame at which initialisation completed (or a loaded map was first
  /// relocalised), counted from this system's first frame; -1 while initialising.
  int InitialisedAtFrame() const;

 private:
  FrameResult Process(const std::shared_ptr<const Frame>& frame, const ImageU8& image);
  /// The deterministic pipeline on one frame, with its events and record (engine lock held).
  FrameResult ProcessInOrder(const std::shared_ptr<const Frame>& frame, const ImageU8& image);
  // Real-time mode (system_realtime.cpp).
  /// Tracks on the caller's thread against the published keyframe; hands the frame on.
  FrameResult ProcessLive(std::int64_t id, double timestamp, const ImageU8& image);
  /// A frame tracked live, with the keyframe rule's verdict on it.
  struct LiveStep {
    TrackingResult tracked;
    double tracking_ms = 0.0;
    bool keep = false;     ///< it asks mapping for a new keyframe
    bool overdue = false;  ///< past the rule by keyframe_wait_factor: the keyframe must exist
  };
  LiveStep TrackLive(const Frame& frame, const LiveSnapshot& snapshot);
  /// Waits for mapping to finish the frame that asked for a keyframe; returns the wait (ms).
  double WaitForRequestedKeyframe();
  /// Records the live pose and hands the frame to mapping.
  FrameResult AnswerLive(const std::shared_ptr<const Frame>& frame, const ImageU8& image,
                         const LiveSnapshot& snapshot, const LiveStep& step);
  /// The mapping thread's work on one frame (takes the engine lock).
  FrameResult MapJob(const MappingJob& job);
  /// After a mapped frame: what the live tracker reads (engine lock held).
  void PublishLive();
  void StartRealtime();
  /// Events the mapping thread left for the caller, appended to `result`.
  void TakePendingEvents(FrameResult* result);
  FrameResult WaitForMapping(const std::shared_ptr<const Frame>& frame, const ImageU8& image,
                             std::optional<LiveTracking> live, LiveTracking hint);
  void ForEachMapPointLocked(const std::function<void(const MapPoint&)>& fn) const;
  std::vector<std::uint8_t> EncodeMapBytesLocked() const;
  void StartKeyframe(const std::shared_ptr<const Frame>& frame, const Sim3d& S_w_kf,
                     InverseDepthMap map, FrameResult* result);
  /// Freezes the current keyframe into the graph and runs the backend on it (real-time mode:
  /// the backend part is deferred until the caller is released).
  void FinishCurrentKeyframe(FrameResult* result);
  /// A keyframe frozen into the graph whose constraint search and optimisation are due.
  struct FinishedKeyframe {
    std::int64_t id = 0;
    std::optional<std::int64_t> parent;  ///< set when it is new (odometry edge to add)
    Sim3d S_parent_kf;
  };
  /// Constraint search, optimisation and place recognition for a finished keyframe, on the
  /// graph (deterministic mode).
  void RunBackend(const FinishedKeyframe& finished, FrameResult* result);
  /// The same on `graph` (the graph or the backend thread's copy of it), counting into
  /// `stats`; events are reported as of frame `frame_id`.
  void RunBackendOn(KeyframeGraph* graph, const FinishedKeyframe& finished, std::int64_t frame_id,
                    BackendStats* stats, std::vector<SystemEvent>* events);
  /// Real-time mode, the backend thread: every keyframe waiting, on a copy of the graph
  /// taken and given back under the engine lock (KeyframeGraph::AdoptOptimised).
  void RunBackendBatch();
  /// Odometry edges (tracking's relative pose, chain_information_) for `keyframes` that
  /// have none to their parent yet.
  void AddChainEdges(KeyframeGraph* graph, const std::vector<FinishedKeyframe>& keyframes) const;
  /// A merge of the map new keyframes join makes them join the merged map.
  void FollowMerges(const std::vector<SystemEvent>& events);
  static void CountOptimisation(const PoseGraphSummary& summary, BackendStats* stats);
  /// Place recognition for the finished keyframe `id` (its entry in the database); a
  /// verified loop becomes an edge.
  void RecognisePlace(KeyframeGraph* graph, std::int64_t id, std::int64_t frame_id,
                      BackendStats* stats, std::vector<SystemEvent>* events);
  /// For a frame lost against the current and recent keyframes: database candidates, PnP on
  /// their depth, direct confirmation; the keyframe found becomes current.
  /// Returns the keyframe found (rebuilt if it was compacted) and the frame tracked on it.
  std::optional<std::pair<std::shared_ptr<const Keyframe>, TrackingResult>> Relocalise(
      const Frame& frame, const ImageU8& image);
  /// Makes keyframe `keyframe` (in the graph) current again: the current one is finished;
  /// its mutable map comes from the recent ones or is rebuilt from its frozen depth.
  void ReturnToKeyframe(const std::shared_ptr<const Keyframe>& keyframe, FrameResult* result);
  /// Recovery from long loss: the lost map's current keyframe is finished and a new map
  /// starts at `frame` (its own world frame until a loop merges it).
  FrameResult StartNewMap(const std::shared_ptr<const Frame>& frame, const ImageU8& image);
  /// kRelocalising: the frame is relocalised on the loaded map or reported lost.
  FrameResult ProcessOnLoadedMap(const std::shared_ptr<const Frame>& frame, const ImageU8& image);
  /// Index of a frame id in frame_poses_ / frame_timestamps_.
  std::size_t FrameIndex(std::int64_t frame_id) const {
    return static_cast<std::size_t>(frame_id - first_frame_id_);
  }
  /// Keyframe-to-world pose of the current keyframe (through its parent while unfinished).
  Sim3d CurrentKeyframePose() const;
  Sim3d KeyframePose(std::int64_t id) const;
  void SetPose(FrameResult* result, const SE3d& T_kf_frame) const;
  RevisedPose Revised(const Frame& frame, const std::optional<SE3d>& T_kf_frame) const;
  void Record(std::int64_t frame_id, const FrameResult& result);
  void ClearMap();
  /// Keyframes other than the current and the recent ones drop their frame and reference.
  void CompactOldKeyframes();
  /// Tries the recent keyframes for a frame lost against the current one (see
  /// SystemOptions::recent_keyframes); on success the found keyframe is current again.
  std::optional<TrackingResult> TrackRecentKeyframes(const Frame& frame, FrameResult* result);
  TrackingResult TrackFrame(const Frame& frame, FrameResult* result);
  void MapFrame(const std::shared_ptr<const Frame>& frame, const ImageU8& image,
                const TrackingResult& tracked, FrameResult* result);
  /// Makes `frame` the new keyframe (depth propagated to it), or reports kDiverged and keeps
  /// the current one when the propagated map diverged.
  void SwitchKeyframe(const std::shared_ptr<const Frame>& frame, const ImageU8& image,
                      const TrackingResult& tracked, FrameResult* result);
  // Initialisation (system_initialization.cpp).
  FrameResult StartFirstKeyframe(const std::shared_ptr<const Frame>& frame, const ImageU8& image);
  std::vector<RevisedPose> FinishInitialisation();
  // Choosing between two starts (start_selection.cpp).
  struct StartSnapshot;
  StartSnapshot SaveStart() const;
  void RestoreStart(StartSnapshot snapshot);
  /// Poses of the buffered frames in the current keyframe (nullopt: lost), in buffer order.
  using BufferedPoses = std::vector<std::optional<SE3d>>;
  /// Mean photometric residual (grey levels) of the buffered frames tracked against the
  /// current map from their buffered poses; a lost frame counts as kLostFrameResidual. The
  /// tracked poses go to `poses`.
  double BufferedResidual(BufferedPoses* poses);
  /// Tracks the buffered frames in order against the current map, updating its depth from
  /// each (as the random start did with its own poses).
  void RefineWithBufferedFrames();
  /// Joint refinement of the first keyframe and the buffered frames (their poses updated).
  void RefineStart(BufferedPoses* poses);
  /// Writes raw and smoothed inverse depths of the current map's `pixel`s and publishes it.
  void SetEstimates(const std::vector<std::int32_t>& pixel, const std::vector<float>& raw,
                    const std::vector<float>& smoothed);

  /// Builds the pair's start refined by the buffered frames and keeps whichever start has
  /// the lower BufferedResidual; returns the buffered frames' poses tracked against the kept
  /// one (its scoring already tracked them all).
  BufferedPoses KeepTheBetterStart(const std::shared_ptr<const Frame>& pair_frame,
                                   const TwoViewPair& pair);
  FrameResult ProcessTwoViewOnly(const std::shared_ptr<const Frame>& frame, const ImageU8& image);
  /// Abandons the start (its poses withdrawn) and starts again on `frame`.
  FrameResult RestartStart(const std::shared_ptr<const Frame>& frame, const ImageU8& image);
  std::optional<FrameResult> ProcessWhileInitialising(const std::shared_ptr<const Frame>& frame,
                                                      const ImageU8& image,
                                                      const TrackingResult& tracked);
  bool RandomStartAgrees(const SE3d& T_kf_frame, const TwoViewPair& pair) const;
  std::optional<SE3d> TrackAgain(const Frame& frame, const SE3d& guess);
  void BufferInitialFrame(const std::shared_ptr<const Frame>& frame, const SE3d& T_kf_frame);
  /// Replaces the first keyframe's depth by stereo with the pair's frame (in initial_frames_)
  /// and tracks every buffered frame again; returns their revised poses, the last one being
  /// the newest frame's.
  std::vector<RevisedPose> StartFromPair(const std::shared_ptr<const Frame>& pair_frame,
                                         const TwoViewPair& pair);
  /// `map`: the keyframe's map before any depth (it is initialised randomly here).
  void StartRandom(const std::shared_ptr<const Frame>& frame, const ImageU8& image,
                   InverseDepthMap map, FrameResult* result);
  /// The newest revision (the frame being processed) becomes the result's own pose.
  void TakeNewestRevision(FrameResult* result) const;

  PinholeCamera camera_;
  SystemOptions options_;
  /// Where the start of the sequence stands (docs/architecture.md, "The start"):
  ///   kNoKeyframe --texture--> kTwoViewSearch (two_view) | kRandomPairSearch (auto) |
  ///   kConverging (random); kTwoViewSearch --pair--> kConverging, --gave up--> kConverging
  ///   (random depth); kRandomPairSearch --pair--> kRandomPairHeld, --gave up--> kConverging;
  ///   kRandomPairHeld --lost: start from the pair--> kConverging; any of them --enough depth
  ///   updates or a keyframe--> kInitialised; --too long lost--> kNoKeyframe (restart).
  ///   A loaded map starts in kRelocalising --relocalised--> kInitialised, --lost for
  ///   new_map_after_lost_s--> a new map (kNoKeyframe).
  enum class StartState {
    kNoKeyframe,        ///< waiting for a frame with enough texture
    kTwoViewSearch,     ///< two_view: keyframe with an empty map, frames only feed the search
    kRandomPairSearch,  ///< auto: random depth tracks while a two-view pair is sought
    kRandomPairHeld,    ///< auto: a pair is held until the random start converges or fails
    kConverging,        ///< the first keyframe's depth converges; no pair work left
    kInitialised,
    kRelocalising,  ///< a loaded map: every frame is relocalised on it until one is found
  };
  StartState start_ = StartState::kNoKeyframe;
  bool mapping_stopped_ = false;  ///< real-time mode: StopMapping ran (no backend left)
  FrameTracker tracker_;
  Mapper mapper_;
  GraphBackend backend_;
  PlaceRecognizer place_;  ///< before loop_closer_, which keeps a pointer to it
  LoopCloser loop_closer_;
  Relocalizer relocalizer_;
  BackendStats backend_stats_;
  /// Finished keyframes and their poses (the map).
  KeyframeGraph graph_;
  /// Where the current keyframe is: in the graph (returned to), or relative to its parent
  /// until it is finished (or, for the first keyframe, in the world).
  struct CurrentKeyframe {
    std::int64_t id = -1;
    std::optional<std::int64_t> parent;
    Sim3d S_parent_kf;  ///< S_w_kf when there is no parent
  };
  CurrentKeyframe current_;
  /// Per frame (index = frame id): its anchored pose, if it has one, and its timestamp.
  std::vector<std::optional<AnchoredPose>> frame_poses_;
  std::vector<double> frame_timestamps_;
  std::int64_t result_frame_id_ = 0;  ///< the frame being processed (for events)
  /// Frame ids: the next one, and this system's first (after the ids of a loaded map).
  std::int64_t frame_count_ = 0;
  std::int64_t first_frame_id_ = 0;
  int frames_unusable_ = 0;
  int depth_updates_ = 0;
  int initialised_at_frame_ = -1;
  /// Frames before initialisation completed, with T_kf_frame (the last good pose if lost),
  /// tracked again against the converged depth; the first keyframe is not among them.
  std::vector<std::pair<std::shared_ptr<const Frame>, SE3d>> initial_frames_;
  int lost_in_a_row_ = 0;
  /// The map new keyframes join, and the id the next new map gets.
  int current_map_ = 0;
  int next_map_ = 1;
  /// Timestamp of the last frame that got a pose (long-loss timer; on a loaded map, of the
  /// first frame given to it).
  double last_posed_timestamp_ = 0.0;
  /// The previous frame got no pose: a frame tracked only "poor" against the same keyframe
  /// is then not trusted (re-acquisition needs an ok match, as recovery does).
  bool previous_frame_lost_ = false;
  std::unique_ptr<TwoViewBootstrap> bootstrap_;  ///< set while a two-view pair is sought
  int bootstrap_tries_ = 0;
  /// Auto: the first good pair, held until the random start has converged (or failed) and
  /// either agrees with it or is replaced by it.
  std::optional<std::pair<std::shared_ptr<const Frame>, TwoViewPair>> pending_pair_;
  /// Locks: engine_mutex_ (everything the mapping stages touch) before poses_mutex_
  /// (frame_poses_, frame_timestamps_, pending_events_); the live tracker's own state is
  /// the caller's. In the deterministic mode they are uncontended.
  mutable std::mutex engine_mutex_;
  mutable std::mutex poses_mutex_;
  /// Changes whenever the current keyframe's depth may be replaced or rescaled as a whole
  /// (the start completing, a restart, a new map): live tracking of an older generation is
  /// not used for depth updates (real-time mode).
  std::uint64_t map_generation_ = 0;
  /// Real-time mode: finished keyframes waiting for the backend thread, and those it works
  /// on (engine lock).
  std::vector<FinishedKeyframe> backend_pending_;
  std::vector<FinishedKeyframe> backend_running_;
  /// Information of an odometry edge the backend did not align (GraphBackend's fallback).
  Matrix7d chain_information_ = Matrix7d::Identity();
  /// Guards place_ (the backend thread adds to it while mapping relocalises on it); taken
  /// after engine_mutex_ when both are.
  mutable std::shared_mutex place_mutex_;
  /// Events of frames mapped behind the caller, for its next result.
  std::vector<SystemEvent> pending_events_;
  std::unique_ptr<LiveTracker> live_;              ///< real-time mode only
  std::unique_ptr<BackendWorker> backend_worker_;  ///< real-time mode only
  std::unique_ptr<MappingWorker> worker_;          ///< real-time mode only; destroyed first
};

}  // namespace parallax
