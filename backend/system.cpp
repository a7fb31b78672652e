#include "backend/system.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "backend/backend_worker.hpp"
#include "backend/live_tracker.hpp"
#include "backend/mapping_worker.hpp"
#include "core/angles.hpp"
#include "core/check.hpp"
#include "core/divergence.hpp"
#include "core/stopwatch.hpp"

namespace parallax {
namespace {

using Clock = StageClock;

}  // namespace

void SystemOptions::Check() const {
  pyramid.Check();
  reference.Check();
  tracker.Check();
  depth.Check();
  update_direction.Check();
  start_refinement.Check();
  CheckOption(start_refinement_frames >= 2, "SystemOptions", "start_refinement_frames", ">= 2");
  keyframe_refinement.Check();
  CheckOption(keyframe_refinement_frames >= 2, "SystemOptions", "keyframe_refinement_frames",
              ">= 2");
  CheckOption(keyframe_refinement_min_window >= 2, "SystemOptions",
              "keyframe_refinement_min_window", ">= 2");
  CheckOption(keyframe_window_capacity >= keyframe_refinement_frames, "SystemOptions",
              "keyframe_window_capacity", ">= keyframe_refinement_frames");
  CheckOption(spread_max_step_change >= 0.0, "SystemOptions", "spread_max_step_change", ">= 0");
  bootstrap.Check();
  quality.Check();
  backend.Check();
  loop_closure.Check();
  relocalization.Check();
  realtime.Check();
  CheckOption(new_map_after_lost_s > 0.0, "SystemOptions", "new_map_after_lost_s", "must be > 0");
  CheckOption(bootstrap_max_frames >= 1, "SystemOptions", "bootstrap_max_frames", "must be >= 1");
  CheckOption(auto_max_rotation_deg > 0.0, "SystemOptions", "auto_max_rotation_deg", "must be > 0");
  CheckOption(auto_max_direction_deg > 0.0, "SystemOptions", "auto_max_direction_deg",
              "must be > 0");
  CheckOption(auto_pair_residual_ratio >= 0.0, "SystemOptions", "auto_pair_residual_ratio",
              "must be >= 0 (0: no comparison)");
  CheckOption(pair_refine_stride >= 1, "SystemOptions", "pair_refine_stride", "must be >= 1");
  CheckOption(restart_after_lost >= 1, "SystemOptions", "restart_after_lost", "must be >= 1");
  CheckOption(max_start_exposure_change > 1.0 && std::isfinite(max_start_exposure_change),
              "SystemOptions", "max_start_exposure_change", "must be > 1 and finite");
  CheckOption(keyframe_distance > 0.0, "SystemOptions", "keyframe_distance", "must be > 0");
  CheckOption(keyframe_rotation_deg >= 0.0 && keyframe_rotation_deg < 180.0, "SystemOptions",
              "keyframe_rotation_deg", "must be in [0, 180) (0 disables)");
  CheckOption(keyframe_rotation_min_rate_deg >= 0.0, "SystemOptions",
              "keyframe_rotation_min_rate_deg", "must be >= 0");
  CheckOption(min_keyframe_usage >= 0.0 && min_keyframe_usage <= 1.0, "SystemOptions",
              "min_keyframe_usage", "must be in [0, 1]");
  CheckOption(min_update_baseline >= 0.0, "SystemOptions", "min_update_baseline", "must be >= 0");
  CheckOption(recent_keyframes >= 0, "SystemOptions", "recent_keyframes", "must be >= 0");
  CheckOption(min_start_texture >= 0.0 && min_start_texture < 1.0, "SystemOptions",
              "min_start_texture", "must be in [0, 1)");
  CheckOption(max_buffered_frames >= 1, "SystemOptions", "max_buffered_frames", "must be >= 1");
  CheckOption(max_buffered_megabytes > 0.0, "SystemOptions", "max_buffered_megabytes",
              "must be > 0");
  CheckOption(min_frames_per_keyframe >= 1, "SystemOptions", "min_frames_per_keyframe",
              "must be >= 1");
  CheckOption(initialization_updates >= 1, "SystemOptions", "initialization_updates",
              "must be >= 1");
  CheckOption(early_keyframe_usage >= 0.0 && early_keyframe_usage < 1.0, "SystemOptions",
              "early_keyframe_usage", "must be in [0, 1) (0 disables)");
}

ParallaxMoments SystemOptions::KeyframeMoments(const InverseDepthMap& map) const {
  if (keyframe_distance_in_image) return ComputeParallaxMoments(map);
  ParallaxMoments mean_only;
  mean_only.mean_idepth = map.MeanSmoothedIdepth();
  return mean_only;
}

double SystemOptions::KeyframeDistance(const ParallaxMoments& parallax,
                                       const Eigen::Vector3d& t_kf_frame) const {
  return keyframe_distance_in_image ? parallax.ImageDistance(t_kf_frame)
                                    : t_kf_frame.norm() * parallax.mean_idepth;
}

double SystemOptions::RotationDeg(const SE3d& T_kf_frame) {
  return T_kf_frame.Rotation().Log().norm() * kRadToDeg;
}

bool SystemOptions::PairRefinesWith(std::size_t index, std::size_t buffered) const {
  // Counted from the newest: it refines last and is the frame tracking goes on from.
  return index < buffered &&
         (buffered - 1 - index) % static_cast<std::size_t>(pair_refine_stride) == 0;
}

bool SystemOptions::WantsKeyframe(int frames_in_keyframe, double relative_distance,
                                  double rotation_deg, const TrackingStats& stats) const {
  const bool view_degrades =
      stats.usage < min_keyframe_usage || stats.good_ratio < min_keyframe_good_ratio;
  // Early only from a consistent frame: the view leaves the keyframe, the pose is sound.
  const bool soon_out_of_view =
      stats.usage < early_keyframe_usage && stats.good_ratio >= min_keyframe_good_ratio;
  return (frames_in_keyframe >= min_frames_per_keyframe || soon_out_of_view) &&
         (view_degrades || relative_distance > keyframe_distance ||
          TurnedPast(frames_in_keyframe, rotation_deg));
}

bool SystemOptions::TurnedPast(int frames_in_keyframe, double rotation_deg, double factor) const {
  return keyframe_rotation_deg > 0.0 && rotation_deg > factor * keyframe_rotation_deg &&
         rotation_deg >= keyframe_rotation_min_rate_deg * std::max(frames_in_keyframe, 1);
}

namespace {

// The options with the tracking references' finest level set to the finest level a tracker
// reads (finer levels are never built).
SystemOptions WithReferenceLevels(SystemOptions options) {
  options.reference.finest_level =
      std::min(options.tracker.finest_level, options.backend.alignment.finest_level);
  return options;
}

}  // namespace

System::System(const PinholeCamera& camera, const SystemOptions& options)
    : camera_(camera),
      options_(WithReferenceLevels(options)),
      tracker_(options.tracker),
      mapper_(camera, options.depth, options.update_direction, options_.reference,
              options.recent_keyframes),
      backend_(options.backend, KeyframeBuildOptions{camera, options.pyramid, options_.reference}),
      place_(Vocabulary::Default(), options.loop_closure.place),
      loop_closer_(options.loop_closure, &place_, camera),
      relocalizer_(options.relocalization, camera),
      window_(static_cast<std::size_t>(std::max(2, options.keyframe_window_capacity))) {
  options_.Check();
  chain_information_ = backend_.FallbackInformation();
  if (options_.realtime.enabled) StartRealtime();
}

Sim3d System::KeyframePose(std::int64_t id) const {
  if (id == current_.id) return CurrentKeyframePose();
  return graph_.Pose(id);
}

Sim3d System::CurrentKeyframePose() const {
  if (graph_.Contains(current_.id)) return graph_.Pose(current_.id);
  if (current_.parent) return graph_.Pose(*current_.parent) * current_.S_parent_kf;
  return current_.S_parent_kf;
}

void System::SetPose(FrameResult* result, const SE3d& T_kf_frame) const {
  result->anchor = AnchoredPose{current_.id, T_kf_frame};
  result->T_w_c = (CurrentKeyframePose() * Sim3d(T_kf_frame)).RigidPart();
}

RevisedPose System::Revised(const Frame& frame, const std::optional<SE3d>& T_kf_frame) const {
  RevisedPose pose;
  pose.frame_id = frame.Id();
  pose.timestamp = frame.Timestamp();
  if (T_kf_frame) {
    pose.keyframe_id = current_.id;
    pose.T_kf_frame = *T_kf_frame;
    pose.T_w_c = (CurrentKeyframePose() * Sim3d(*T_kf_frame)).RigidPart();
  }
  return pose;
}

void System::StartKeyframe(const std::shared_ptr<const Frame>& frame, const Sim3d& S_w_kf,
                           InverseDepthMap map, FrameResult* result) {
  CurrentKeyframe next{frame->Id(), std::nullopt, S_w_kf};
  if (mapper_.HasMap()) {
    // Relative to the keyframe it grew from, before the backend moves that one.
    next.parent = current_.id;
    next.S_parent_kf = CurrentKeyframePose().Inverse() * S_w_kf;
    tracked_keyframes_[next.id] = TrackedKeyframe{current_.id, next.S_parent_kf};
    FinishCurrentKeyframe(result);
    mapper_.Retire();
  }
  current_ = next;
  mapper_.SetMap(std::move(map));
  CompactOldKeyframes();
  tracker_.StartKeyframe();
  result->events.push_back({SystemEvent::Kind::kKeyframeCreated, frame->Id(), frame->Id()});
}

void System::CompactOldKeyframes() { graph_.Compact(mapper_.LiveKeyframeIds()); }

void System::Record(std::int64_t frame_id, const FrameResult& result) {
  const std::lock_guard<std::mutex> lock(poses_mutex_);
  const std::size_t index = FrameIndex(frame_id);
  frame_poses_.resize(std::max(frame_poses_.size(), index + 1));
  frame_poses_[index] = result.anchor;
  for (const RevisedPose& r : result.revised) {
    // The frame that completes initialisation is among the revised ones: its pose tracked
    // again on the converged depth is the better one (TUM clip: 5.9 mm against 14.9 with the
    // live pose), unless the frame became the next keyframe, which is anchored at itself.
    if (r.frame_id == frame_id && result.is_keyframe) continue;
    auto& pose = frame_poses_[FrameIndex(r.frame_id)];
    pose.reset();
    if (r.T_w_c) pose = AnchoredPose{r.keyframe_id, r.T_kf_frame};
  }
}

void System::ClearMap() {
  // A failed start of a later map keeps the earlier maps (no keyframe of the failed start
  // was finished: initialisation completes before any keyframe is left).
  // No backend work can be running then (real-time mode): it only follows finished keyframes.
  if (current_map_ == 0) {
    graph_.Clear();
    const std::unique_lock<std::shared_mutex> place(place_mutex_);
    place_.Clear();
    loop_closer_.Clear();
  }
  mapper_.Clear();
  window_.Clear();
  current_ = CurrentKeyframe{};
  ++map_generation_;
}

FrameResult System::ProcessFrame(const ImageU8& image, double timestamp) {
  CheckArgument(std::isfinite(timestamp), "System::ProcessFrame: timestamp is not finite");
  CheckArgument(image.Width() == camera_.Width() && image.Height() == camera_.Height(),
                "System::ProcessFrame: image is " + std::to_string(image.Width()) + "x" +
                    std::to_string(image.Height()) + ", the camera " +
                    std::to_string(camera_.Width()) + "x" + std::to_string(camera_.Height()));
  const FrameQuality quality =
      AssessFrame(image, options_.quality,
                  camera_.Validity() != nullptr ? &camera_.Validity()->Level(0) : nullptr);
  const std::int64_t id = frame_count_++;
  {
    const std::lock_guard<std::mutex> lock(poses_mutex_);
    frame_timestamps_.push_back(timestamp);
  }
  if (!quality.Usable()) {
    // No tracking and no depth update from it: nothing of the map or the motion changes.
    ++frames_unusable_;
    FrameResult result;
    result.stats.reason = quality.Reason();
    result.events.push_back({SystemEvent::Kind::kLost, id, -1});
    Record(id, result);
    TakePendingEvents(&result);
    if (live_) {
      live_->previous_lost = true;
    } else {
      previous_frame_lost_ = true;
    }
    return result;
  }
  if (live_) {
    FrameResult result = ProcessLive(id, timestamp, image);
    // A start frame answered before it was mapped is not lost (it was not tried).
    live_->previous_lost = !result.T_w_c && !result.answered_before_mapping;
    return result;
  }
  auto frame = std::make_shared<const Frame>(id, timestamp, camera_, image, options_.pyramid);
  const std::lock_guard<std::mutex> lock(engine_mutex_);
  return ProcessInOrder(frame, image);
}

FrameResult System::ProcessInOrder(const std::shared_ptr<const Frame>& frame, const ImageU8& image,
                                   DepthWork work) {
  result_frame_id_ = frame->Id();
  FrameResult result = Process(frame, image, work);
  if (!result.T_w_c) result.events.push_back({SystemEvent::Kind::kLost, frame->Id(), -1});
  if (!result.revised.empty()) {
    result.events.push_back({SystemEvent::Kind::kPosesRevised, frame->Id(), -1});
  }
  if (result.T_w_c) last_posed_timestamp_ = frame->Timestamp();
  previous_frame_lost_ = !result.T_w_c;
  result.initialising = start_ != StartState::kInitialised && start_ != StartState::kRelocalising;
  Record(frame->Id(), result);
  return result;
}

FrameResult System::Process(const std::shared_ptr<const Frame>& frame, const ImageU8& image,
                            DepthWork work) {
  if (start_ == StartState::kNoKeyframe) return StartFirstKeyframe(frame, image);
  if (start_ == StartState::kRelocalising) return ProcessOnLoadedMap(frame, image);
  if (start_ == StartState::kTwoViewSearch) return ProcessTwoViewOnly(frame, image);
  FrameResult result;
  TrackingResult tracked = TrackFrame(*frame, &result);
  if (tracked.status == TrackingStatus::kLost && start_ == StartState::kInitialised) {
    if (auto recovered = TrackRecentKeyframes(*frame, &result)) {
      tracked = std::move(*recovered);
      result.status = tracked.status;
      result.stats = tracked.stats;
      result.stats.reason = "recovered on a recent keyframe";
      SetPose(&result, tracked.T_kf_frame);
      result.events.push_back({SystemEvent::Kind::kRecovered, frame->Id(), current_.id});
    } else if (auto relocalised = Relocalise(*frame, image)) {
      tracked = std::move(relocalised->second);
      result.status = tracked.status;
      result.stats = tracked.stats;
      result.stats.reason = "relocalised";
      ReturnToKeyframe(relocalised->first, &result);
      tracker_.SetState(MotionState{tracked.T_kf_frame, SE3d(), tracked.affine, 1});
      SetPose(&result, tracked.T_kf_frame);
      result.events.push_back({SystemEvent::Kind::kRelocalised, frame->Id(), current_.id});
    } else if (frame->Timestamp() - last_posed_timestamp_ >= options_.new_map_after_lost_s) {
      return StartNewMap(frame, image);
    }
  }
  if (start_ != StartState::kInitialised) {
    if (auto handled = ProcessWhileInitialising(frame, image, tracked)) return *handled;
  }
  if (tracked.status != TrackingStatus::kLost) MapFrame(frame, image, tracked, &result, work);
  return result;
}

TrackingResult System::TrackFrame(const Frame& frame, FrameResult* result) {
  const auto start = Clock::now();
  TrackingResult tracked;
  const MotionState before = tracker_.State();
  try {
    tracked = tracker_.Track(*mapper_.Reference(), frame);
  } catch (const NumericalDivergence& e) {
    // The tracker's state changes only after a result: it is as before this frame.
    tracked = DivergedTracking(e);
    ++backend_stats_.frames_diverged;
    result->events.push_back({SystemEvent::Kind::kDiverged, frame.Id(), current_.id});
  }
  result->tracking_ms = MillisecondsSince(start);
  if (tracked.status != TrackingStatus::kLost && !tracker_.Reacquires(tracked) &&
      previous_frame_lost_ && start_ == StartState::kInitialised) {
    // Just below the lost threshold for a run of frames, then just above it, is the same
    // wrong alignment, not a re-acquisition (a 29 degree error was accepted that way).
    tracked.status = TrackingStatus::kLost;
    tracked.stats.reason =
        "not confident right after a lost frame (re-acquisition needs ok, "
        "not suspect)";
    tracker_.SetState(before);
  }
  result->status = tracked.status;
  result->stats = tracked.stats;
  if (tracked.status == TrackingStatus::kLost) return tracked;  // the last good state is kept
  SetPose(result, tracked.T_kf_frame);
  return tracked;
}

void System::MapFrame(const std::shared_ptr<const Frame>& frame, const ImageU8& image,
                      const TrackingResult& tracked, FrameResult* result, DepthWork work,
                      bool keyframe_asked) {
  const auto start = Clock::now();
  // Distance relative to the mean depth (mean idepth is 1 after normalisation): the depth
  // updates' baseline, and the keyframe rule's distance (or, with keyframe_distance_in_image,
  // that distance as the image sees it).
  const ParallaxMoments parallax = options_.KeyframeMoments(mapper_.Map());
  const Eigen::Vector3d& t_kf_frame = tracked.T_kf_frame.Translation();
  const double relative_distance = t_kf_frame.norm() * parallax.mean_idepth;
  // While a two-view pair is sought or held the first keyframe stays: the random start it
  // would be compared with, or replaced by, lives in that keyframe.
  const bool start_pending =
      start_ == StartState::kRandomPairSearch || start_ == StartState::kRandomPairHeld;
  // A keyframe the live tracker asked for is made although the depth refined since its
  // snapshot may have moved the rule's distance just below the bound: the live tracker
  // does not ask twice for one keyframe, and would otherwise wait for it once overdue.
  const bool want_keyframe =
      !start_pending &&
      (keyframe_asked ||
       options_.WantsKeyframe(tracker_.State().frames_in_keyframe,
                              options_.KeyframeDistance(parallax, t_kf_frame),
                              SystemOptions::RotationDeg(tracked.T_kf_frame), tracked.stats));
  const bool refines =
      work == DepthWork::kRefine ||
      mapper_.Map().updates < static_cast<std::uint32_t>(options_.realtime.catch_up_refinements);
  if (!refines && live_) ++live_->caught_up;
  if (refines && tracked.status == TrackingStatus::kOk &&
      relative_distance > options_.min_update_baseline) {
    // Only once initialised: the start's keyframe and its selection stay as they were.
    const bool initialised = start_ == StartState::kInitialised;
    const SE3d T_kf_update =
        !initialised ? tracked.T_kf_frame
                     : mapper_.Direction().Refine(mapper_.KeyframeId(), image, tracked.T_kf_frame,
                                                  relative_distance);
    backend_stats_.depth_estimates_diverged +=
        mapper_.Update(*frame, T_kf_update, tracked).diverged;
    ++depth_updates_;
    if (!want_keyframe) mapper_.PublishReference();
    if (initialised && options_.keyframe_refinement.enabled) {
      window_.Add(mapper_.KeyframeId(), frame, tracked.T_kf_frame);
    }
  }
  if (start_ != StartState::kInitialised) {
    BufferInitialFrame(frame, tracked.T_kf_frame);
    if (depth_updates_ >= options_.initialization_updates || want_keyframe) {
      if (want_keyframe) mapper_.PublishReference();
      result->revised = FinishInitialisation();
    }
  }
  // ok or poor: a degrading view is the reason to switch
  if (want_keyframe) SwitchKeyframe(frame, image, tracked, result);
  result->mapping_ms = MillisecondsSince(start);
}

void System::SwitchKeyframe(const std::shared_ptr<const Frame>& frame, const ImageU8& image,
                            const TrackingResult& tracked, FrameResult* result) {
  RefineLeavingKeyframe();
  std::optional<std::pair<InverseDepthMap, float>> propagated;
  try {
    PropagationStats stats;
    propagated = mapper_.Propagate(frame, tracked, &stats);
    backend_stats_.depth_estimates_diverged += stats.diverged;
  } catch (const NumericalDivergence&) {
    // The propagated map diverged: no keyframe from it. The frame keeps its tracked pose and
    // the current keyframe stays; the next frame that wants a keyframe tries again.
    ++backend_stats_.keyframes_diverged;
    result->events.push_back({SystemEvent::Kind::kDiverged, frame->Id(), current_.id});
    return;
  }
  auto& [next, s] = *propagated;
  // Normalising multiplies idepth by s, so a point's new-keyframe coordinates become
  // p' = p / s; the keyframe-to-world similarity absorbs it: S_w_new = S_w_c * Sim3(s).
  const Sim3d S_w_c = CurrentKeyframePose() * Sim3d(tracked.T_kf_frame);
  const MotionState last = tracker_.State();
  const SE3d velocity(last.T_prev_last.Rotation(), last.T_prev_last.Translation() / s);
  StartKeyframe(frame, S_w_c * Sim3d(s, SO3d(), Eigen::Vector3d::Zero()), std::move(next), result);
  SetPose(result, SE3d());  // the frame is the new keyframe
  mapper_.Direction().SetKeyframe(frame->Id(), image);
  // Constant-velocity guess for the next frame in the new keyframe's units.
  tracker_.SetState(MotionState{SE3d(), velocity, AffineBrightness{}, 0, last.last_timestamp,
                                last.velocity_interval, last.residual_rms});
  result->is_keyframe = true;
}

std::vector<Eigen::Vector3f> System::MapPoints() const {
  std::vector<Eigen::Vector3f> all;
  ForEachMapPoint([&](const MapPoint& p) { all.push_back(p.p_w); });
  return all;
}

void System::ForEachMapPoint(const std::function<void(const MapPoint&)>& fn) const {
  const std::lock_guard<std::mutex> lock(engine_mutex_);
  ForEachMapPointLocked(fn);
}

void System::ForEachMapPointLocked(const std::function<void(const MapPoint&)>& fn) const {
  graph_.ForEachMapPoint(camera_, fn);
  if (mapper_.HasMap() && !graph_.Contains(current_.id)) {
    // The current keyframe's confirmed points, through its current pose.
    const InverseDepthMap& map = mapper_.Map();
    const Sim3d S_w_kf = CurrentKeyframePose();
    const PinholeCamera& K = map.Keyframe().Camera(0);
    const PyramidLevel& image = map.Keyframe().Level(0);
    for (int y = 0; y < map.Height(); ++y) {
      for (int x = 0; x < map.Width(); ++x) {
        const std::size_t i = map.Index(x, y);
        if (!map.IsConfirmed(i)) continue;
        const Eigen::Vector3d p = K.Unproject(Eigen::Vector2d(x, y)) / map.idepth_smoothed[i];
        const auto grey =
            static_cast<std::uint8_t>(std::lround(std::clamp(image.intensity(x, y), 0.0f, 255.0f)));
        fn(MapPoint{(S_w_kf * p).cast<float>(), grey});
      }
    }
  }
}

std::vector<KeyframeRecord> System::Keyframes() const {
  const std::lock_guard<std::mutex> engine(engine_mutex_);
  std::vector<KeyframeRecord> records;
  for (const std::int64_t id : graph_.Ids()) {
    records.push_back({id, graph_.Get(id).timestamp, graph_.Pose(id), graph_.MapOf(id)});
  }
  if (mapper_.HasMap() && !graph_.Contains(current_.id)) {
    records.push_back({current_.id, mapper_.Map().KeyframePtr()->Timestamp(), CurrentKeyframePose(),
                       current_map_});
  }
  return records;
}

std::vector<FramePose> System::Trajectory() const {
  const std::lock_guard<std::mutex> engine(engine_mutex_);
  const std::lock_guard<std::mutex> frames(poses_mutex_);
  FrameAnchors anchored;
  anchored.anchors = &frame_poses_;
  anchored.first_frame_id = first_frame_id_;
  anchored.tracked = &tracked_keyframes_;
  anchored.max_step_change = options_.spread_max_step_change;
  anchored.keyframe_pose = [this](std::int64_t id) -> std::optional<Sim3d> {
    // A keyframe of a map discarded by a restart: its frames have no pose any more.
    if (id != current_.id && !graph_.Contains(id)) return std::nullopt;
    return KeyframePose(id);
  };
  std::vector<FramePose> poses = FrameWorldPoses(anchored, options_.spread_keyframe_corrections);
  for (FramePose& pose : poses) pose.timestamp = frame_timestamps_[FrameIndex(pose.frame_id)];
  return poses;
}

void BackendStats::Add(const BackendStats& other) {
  optimisations += other.optimisations;
  iterations += other.iterations;
  alignments += other.alignments;
  edges_rejected += other.edges_rejected;
  optimisation_ms.insert(optimisation_ms.end(), other.optimisation_ms.begin(),
                         other.optimisation_ms.end());
  loop_candidates += other.loop_candidates;
  loop_checks += other.loop_checks;
  loops_rejected += other.loops_rejected;
  loops_closed += other.loops_closed;
  loop_ms.insert(loop_ms.end(), other.loop_ms.begin(), other.loop_ms.end());
  relocalisation_attempts += other.relocalisation_attempts;
  relocalisations += other.relocalisations;
  maps_started += other.maps_started;
  merges += other.merges;
  frames_diverged += other.frames_diverged;
  depth_estimates_diverged += other.depth_estimates_diverged;
  keyframes_diverged += other.keyframes_diverged;
  backend_steps_diverged += other.backend_steps_diverged;
}

BackendStats System::Backend() const {
  const std::lock_guard<std::mutex> lock(engine_mutex_);
  return backend_stats_;
}

int System::CurrentMap() const {
  const std::lock_guard<std::mutex> lock(engine_mutex_);
  return current_map_;
}

std::size_t System::PlaceRecognitionBytes() const {
  const std::shared_lock<std::shared_mutex> place(place_mutex_);
  return place_.Bytes();
}

int System::InitialisedAtFrame() const {
  const std::lock_guard<std::mutex> lock(engine_mutex_);
  return initialised_at_frame_;
}

bool System::Initialising() const {
  const std::lock_guard<std::mutex> lock(engine_mutex_);
  return start_ != StartState::kInitialised && start_ != StartState::kRelocalising;
}

bool System::AwaitingRelocalisation() const {
  const std::lock_guard<std::mutex> lock(engine_mutex_);
  return start_ == StartState::kRelocalising;
}

}  // namespace parallax
