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
#include "backend/frame_trajectory.hpp"
#include "backend/graph_backend.hpp"
#include "backend/keyframe_graph.hpp"
#include "backend/keyframe_refinement.hpp"
#include "backend/keyframe_window.hpp"
#include "backend/loop_closer.hpp"
#include "backend/mapper.hpp"
#include "backend/place_recognizer.hpp"
#include "backend/relocalizer.hpp"
#include "backend/system_options.hpp"
#include "backend/system_results.hpp"
#include "backend/two_view_bootstrap.hpp"
#include "backend/update_direction.hpp"
#include "core/frame.hpp"
#include "core/frame_quality.hpp"
#include "core/image.hpp"
#include "core/pinhole_camera.hpp"
#include "core/sim3.hpp"
#include "core/stopwatch.hpp"
#include "core/validity_mask.hpp"
#include "depth/depth_filter.hpp"
#include "tracking/se3_tracker.hpp"
#include "tracking/tracking_reference.hpp"

namespace parallax {

struct MappingJob;
struct LiveTracking;
struct LiveSnapshot;
struct LiveBridge;
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
  /// What mapping does with a tracked frame besides the keyframe rule: refine the keyframe's
  /// depth with it, or only while the keyframe has had few updates (the real-time catch-up
  /// after the start, docs/realtime.md).
  enum class DepthWork { kRefine, kRefineYoungKeyframe };
  FrameResult Process(const std::shared_ptr<const Frame>& frame, const ImageU8& image,
                      DepthWork work);
  /// The deterministic pipeline on one frame, with its events and record (engine lock held).
  FrameResult ProcessInOrder(const std::shared_ptr<const Frame>& frame, const ImageU8& image,
                             DepthWork work = DepthWork::kRefine);
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
  /// The same on the bridge (its step's pose and brightness re-expressed in the keyframe;
  /// `overdue` measured from the bridge's frame, `keep` false).
  LiveStep TrackOnBridge(const Frame& frame, const LiveSnapshot& snapshot,
                         const LiveBridge& bridge);
  /// The bridge made for the keyframe request pending in the snapshot's keyframe (null:
  /// none).
  LiveBridge* PendingBridge(const LiveSnapshot& snapshot);
  /// A live frame tracked on the keyframe, or on the pending bridge once a frame was
  /// overdue on the keyframe (measured, or predicted by PredictedOverdue); `before`: the
  /// tracker's state before the frame.
  LiveStep TrackKeyframeOrBridge(const Frame& frame, const LiveSnapshot& snapshot,
                                 const MotionState& before);
  /// Whether the motion model's guess for `frame` is already past the keyframe rule's
  /// distance or turn by keyframe_wait_factor (the overdue test without the tracking
  /// statistics).
  bool PredictedOverdue(const Frame& frame, const LiveSnapshot& snapshot) const;
  /// The tracking call of TrackLive and TrackOnBridge: timed, divergence reported as lost.
  LiveStep TrackOn(const TrackingReference& reference, const Frame& frame);
  /// The keyframe rule (keep) and its overdue test on a live tracking result `t` whose pose
  /// is relative to the reference the rule is measured from.
  void JudgeKeyframeRule(const LiveSnapshot& snapshot, LiveStep* step) const;
  /// Waits for mapping to finish the frame that asked for a keyframe; returns the wait (ms).
  double WaitForRequestedKeyframe();
  /// Pacing (RealtimeOptions::keyframe_pacing_ms): while the keyframe a frame asked for is
  /// pending, waits for it within the call's budget from `call_start`; returns the snapshot
  /// to track against (the new keyframe's when it came) and adds the wait to `*waited_ms`.
  LiveSnapshot PaceForRequestedKeyframe(LiveSnapshot snapshot, StageClock::time_point call_start,
                                        double* waited_ms);
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
  /// Before the map is initialised: hands the frame to mapping and answers without a pose.
  FrameResult QueueStartFrame(std::int64_t id, double timestamp, const ImageU8& image);
  /// After start frames were queued: once the start is usable, waits until mapping has done
  /// them and adopts its state; returns the snapshot to track against.
  LiveSnapshot CatchUpWithStart(LiveSnapshot snapshot);
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
  /// Depth update and keyframe rule for a tracked frame. `keyframe_asked`: the live
  /// tracker's rule asked for a keyframe at this frame, on the keyframe and map this thread
  /// has (the real-time mode); its verdict stands.
  void MapFrame(const std::shared_ptr<const Frame>& frame, const ImageU8& image,
                const TrackingResult& tracked, FrameResult* result,
                DepthWork work = DepthWork::kRefine, bool keyframe_asked = false);
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
  /// Before the current keyframe is left: when SystemOptions::keyframe_refinement is on and
  /// its window is long enough, its depth is refined jointly with the window's frames
  /// (system_refinement.cpp), so the next keyframe inherits the refined depth. The window is
  /// emptied either way.
  void RefineLeavingKeyframe();
  /// Writes raw and smoothed inverse depths of the current map's `pixel`s and publishes it.
  void SetEstimates(const std::vector<std::int32_t>& pixel, const std::vector<float>& raw,
                    const std::vector<float>& smoothed);

  /// Builds the pair's start refined by the buffered frames and keeps whichever start has
  /// the lower BufferedResidual; returns the buffered frames' poses tracked against the kept
  /// one (its scoring already tracked them all).
  BufferedPoses KeepTheBetterStart(const std::shared_ptr<const Frame>& pair_frame,
                                   const TwoViewPair& pair);
  FrameResult ProcessTwoViewOnly(const std::shared_ptr<const Frame>& frame, const ImageU8& image);
  /// Ends the search for a two-view pair: the bootstrap and any fallback pair are dropped.
  void EndPairSearch();
  /// Abandons the start (its poses withdrawn) and starts again on `frame`.
  FrameResult RestartStart(const std::shared_ptr<const Frame>& frame, const ImageU8& image);
  std::optional<FrameResult> ProcessWhileInitialising(const std::shared_ptr<const Frame>& frame,
                                                      const ImageU8& image,
                                                      const TrackingResult& tracked);
  bool RandomStartAgrees(const SE3d& T_kf_frame, const TwoViewPair& pair) const;
  /// A frame posed before, tracked again on the current (refined) map from that pose
  /// (FrameTracker::Retrack); nullopt when lost. `previous`: the result of the frame before it,
  /// tracked again just before; when this one explains clearly fewer points, the frame is also
  /// tracked from that frame's pose and the result that explains more is kept.
  std::optional<TrackingResult> TrackAgain(const Frame& frame, const SE3d& guess,
                                           const std::optional<TrackingResult>& previous);
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
  /// Every keyframe that grew from another: where tracking placed it (FrameWorldPoses).
  std::map<std::int64_t, TrackedKeyframe> tracked_keyframes_;
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
  /// Frames that updated the current keyframe's depth (only with keyframe_refinement on).
  KeyframeWindow window_;
  /// The map new keyframes join, and the id the next new map gets.
  int current_map_ = 0;
  int next_map_ = 1;
  /// Timestamp of the last frame that got a pose (long-loss timer; on a loaded map, of the
  /// first frame given to it).
  double last_posed_timestamp_ = 0.0;
  /// The previous frame got no pose: a frame tracked against the same keyframe is then
  /// trusted only when FrameTracker::Reacquires (as for recovery and relocalisation).
  bool previous_frame_lost_ = false;
  std::unique_ptr<TwoViewBootstrap> bootstrap_;  ///< set while a two-view pair is sought
  int bootstrap_tries_ = 0;
  /// Auto: the first good pair, held until the random start has converged (or failed) and
  /// either agrees with it or is replaced by it.
  std::optional<std::pair<std::shared_ptr<const Frame>, TwoViewPair>> pending_pair_;
  /// Auto, while no pair is good enough: the pair with the most parallax among those that
  /// failed only on parallax (min_fallback_parallax_deg), taken if the random start is lost.
  std::optional<std::pair<std::shared_ptr<const Frame>, TwoViewPair>> fallback_pair_;
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
