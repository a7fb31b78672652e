#include "backend/system.hpp"

#include <chrono>
#include <cmath>

#include "core/check.hpp"

namespace parallax {
namespace {

using Clock = std::chrono::steady_clock;

double MillisecondsSince(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

}  // namespace

void SystemOptions::Check() const {
  pyramid.Check();
  reference.Check();
  tracker.Check();
  depth.Check();
  update_direction.Check();
  bootstrap.Check();
  backend.Check();
  CheckOption(bootstrap_max_frames >= 1, "SystemOptions", "bootstrap_max_frames", "must be >= 1");
  CheckOption(auto_max_rotation_deg > 0.0, "SystemOptions", "auto_max_rotation_deg", "must be > 0");
  CheckOption(auto_max_direction_deg > 0.0, "SystemOptions", "auto_max_direction_deg",
              "must be > 0");
  CheckOption(auto_pair_residual_ratio > 0.0, "SystemOptions", "auto_pair_residual_ratio",
              "must be > 0");
  CheckOption(restart_after_lost >= 1, "SystemOptions", "restart_after_lost", "must be >= 1");
  CheckOption(keyframe_distance > 0.0, "SystemOptions", "keyframe_distance", "must be > 0");
  CheckOption(min_keyframe_usage >= 0.0 && min_keyframe_usage <= 1.0, "SystemOptions",
              "min_keyframe_usage", "must be in [0, 1]");
  CheckOption(min_update_baseline >= 0.0, "SystemOptions", "min_update_baseline", "must be >= 0");
  CheckOption(recent_keyframes >= 0, "SystemOptions", "recent_keyframes", "must be >= 0");
  CheckOption(min_start_texture >= 0.0 && min_start_texture < 1.0, "SystemOptions",
              "min_start_texture", "must be in [0, 1)");
  CheckOption(max_buffered_frames >= 1, "SystemOptions", "max_buffered_frames", "must be >= 1");
  CheckOption(min_frames_per_keyframe >= 1, "SystemOptions", "min_frames_per_keyframe",
              "must be >= 1");
  CheckOption(initialization_updates >= 1, "SystemOptions", "initialization_updates",
              "must be >= 1");
}

System::System(const PinholeCamera& camera, const SystemOptions& options)
    : camera_(camera),
      options_(options),
      tracker_(options.tracker),
      depth_filter_(options.depth),
      update_direction_(camera, options.update_direction),
      backend_(options.backend, KeyframeBuildOptions{camera, options.pyramid, options.reference}) {
  options_.Check();
}

void System::RebuildReference() {
  ImageF idepth, variance;
  map_->ExportSmoothed(&idepth, &variance);
  reference_ = std::make_shared<const TrackingReference>(map_->KeyframePtr(), idepth, variance,
                                                         options_.reference);
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

void System::FinishCurrentKeyframe(FrameResult* result) {
  auto keyframe = std::make_shared<Keyframe>();
  keyframe->id = map_->KeyframePtr()->Id();
  keyframe->timestamp = map_->KeyframePtr()->Timestamp();
  keyframe->frame = map_->KeyframePtr();
  const PyramidLevel& level0 = keyframe->frame->Level(0);
  keyframe->image = ImageU8(level0.Width(), level0.Height());
  for (int y = 0; y < level0.Height(); ++y) {
    for (int x = 0; x < level0.Width(); ++x) {
      keyframe->image(x, y) = static_cast<std::uint8_t>(std::lround(level0.intensity(x, y)));
    }
  }
  keyframe->depth = FrozenDepth::FromMap(*map_);
  keyframe->reference = reference_;
  const bool is_new = !graph_.Contains(keyframe->id);
  graph_.Upsert(keyframe, CurrentKeyframePose());
  result->events.push_back({SystemEvent::Kind::kKeyframeFinished, result_frame_id_, keyframe->id});
  if (!options_.optimize_graph) {
    if (is_new && current_.parent) {
      graph_.AddEdge(PoseGraphEdge{*current_.parent, keyframe->id, current_.S_parent_kf,
                                   Matrix7d::Identity(), EdgeKind::kOdometry});
    }
    return;
  }
  const auto start = Clock::now();
  const BackendReport report = backend_.KeyframeFinished(
      &graph_, keyframe->id, is_new ? current_.parent : std::nullopt, current_.S_parent_kf);
  backend_stats_.alignments += report.alignments;
  backend_stats_.edges_rejected += report.edges_rejected;
  if (report.optimisation) {
    ++backend_stats_.optimisations;
    backend_stats_.iterations += report.optimisation->iterations;
    backend_stats_.optimisation_ms.push_back(MillisecondsSince(start));
    result->events.push_back({SystemEvent::Kind::kGraphOptimised, result_frame_id_, keyframe->id});
  }
}

void System::StartKeyframe(const std::shared_ptr<const Frame>& frame, const Sim3d& S_w_kf,
                           InverseDepthMap map, FrameResult* result) {
  CurrentKeyframe next{frame->Id(), std::nullopt, S_w_kf};
  if (map_) {
    // Relative to the keyframe it grew from, before the backend moves that one.
    next.parent = current_.id;
    next.S_parent_kf = CurrentKeyframePose().Inverse() * S_w_kf;
    FinishCurrentKeyframe(result);
    if (options_.recent_keyframes > 0) {
      recent_.push_front({std::move(map_), std::move(reference_)});
      if (static_cast<int>(recent_.size()) > options_.recent_keyframes) recent_.pop_back();
    }
  }
  current_ = next;
  CompactOldKeyframes();
  map_ = std::make_unique<InverseDepthMap>(std::move(map));
  T_kf_last_ = SE3d();
  T_prev_last_ = SE3d();
  frames_in_keyframe_ = 0;
  RebuildReference();
  result->events.push_back({SystemEvent::Kind::kKeyframeCreated, frame->Id(), frame->Id()});
}

void System::CompactOldKeyframes() {
  std::vector<std::int64_t> keep{current_.id};
  for (const RecentKeyframe& r : recent_) keep.push_back(r.map->KeyframePtr()->Id());
  graph_.Compact(keep);
}

void System::Record(std::int64_t frame_id, const FrameResult& result) {
  const auto index = static_cast<std::size_t>(frame_id);
  frame_poses_.resize(std::max(frame_poses_.size(), index + 1));
  frame_poses_[index] = result.anchor;
  for (const RevisedPose& r : result.revised) {
    // The frame that completes initialisation is among the revised ones: its pose tracked
    // again on the converged depth is the better one (TUM clip: 5.9 mm against 14.9 with the
    // live pose), unless the frame became the next keyframe, which is anchored at itself.
    if (r.frame_id == frame_id && result.is_keyframe) continue;
    auto& pose = frame_poses_[static_cast<std::size_t>(r.frame_id)];
    pose.reset();
    if (r.T_w_c) pose = AnchoredPose{r.keyframe_id, r.T_kf_frame};
  }
}

void System::ClearMap() {
  graph_.Clear();
  recent_.clear();
  map_.reset();
  reference_.reset();
  current_ = CurrentKeyframe{};
}

FrameResult System::ProcessFrame(const ImageU8& image, double timestamp) {
  CheckArgument(std::isfinite(timestamp), "System::ProcessFrame: timestamp is not finite");
  CheckArgument(image.Width() == camera_.Width() && image.Height() == camera_.Height(),
                "System::ProcessFrame: image is " + std::to_string(image.Width()) + "x" +
                    std::to_string(image.Height()) + ", the camera " +
                    std::to_string(camera_.Width()) + "x" + std::to_string(camera_.Height()));
  auto frame =
      std::make_shared<const Frame>(frame_count_, timestamp, camera_, image, options_.pyramid);
  ++frame_count_;
  frame_timestamps_.push_back(timestamp);
  result_frame_id_ = frame->Id();
  FrameResult result = Process(frame, image);
  if (!result.T_w_c) result.events.push_back({SystemEvent::Kind::kLost, frame->Id(), -1});
  if (!result.revised.empty()) {
    result.events.push_back({SystemEvent::Kind::kPosesRevised, frame->Id(), -1});
  }
  Record(frame->Id(), result);
  return result;
}

FrameResult System::Process(const std::shared_ptr<const Frame>& frame, const ImageU8& image) {
  if (!map_) return StartFirstKeyframe(frame, image);
  if (options_.initialization == Initialization::kTwoView && bootstrap_) {
    return ProcessTwoViewOnly(frame, image);
  }
  FrameResult result;
  TrackingResult tracked = TrackFrame(*frame, &result);
  if (tracked.status == TrackingStatus::kLost && initialised_at_frame_ >= 0) {
    if (auto recovered = TrackRecentKeyframes(*frame, &result)) {
      tracked = std::move(*recovered);
      result.status = tracked.status;
      result.stats = tracked.stats;
      result.stats.reason = "recovered on a recent keyframe";
      SetPose(&result, tracked.T_kf_frame);
      result.events.push_back({SystemEvent::Kind::kRecovered, frame->Id(), current_.id});
    }
  }
  if (initialised_at_frame_ < 0) {
    if (auto handled = ProcessWhileInitialising(frame, image, tracked)) return *handled;
  }
  if (tracked.status != TrackingStatus::kLost) MapFrame(frame, image, tracked, &result);
  return result;
}

TrackingResult System::TrackFrame(const Frame& frame, FrameResult* result) {
  const auto start = Clock::now();
  TrackingResult tracked =
      tracker_.Track(*reference_, frame, MotionHypotheses(T_kf_last_, T_prev_last_), affine_);
  result->tracking_ms = MillisecondsSince(start);
  result->status = tracked.status;
  result->stats = tracked.stats;
  if (tracked.status == TrackingStatus::kLost) return tracked;  // keep the last good state
  T_prev_last_ = T_kf_last_.Inverse() * tracked.T_kf_frame;
  T_kf_last_ = tracked.T_kf_frame;
  affine_ = tracked.affine;
  ++frames_in_keyframe_;
  SetPose(result, tracked.T_kf_frame);
  return tracked;
}

void System::MapFrame(const std::shared_ptr<const Frame>& frame, const ImageU8& image,
                      const TrackingResult& tracked, FrameResult* result) {
  const auto start = Clock::now();
  // Distance relative to the mean depth (mean idepth is 1 after normalisation).
  const double relative_distance =
      tracked.T_kf_frame.Translation().norm() * map_->MeanSmoothedIdepth();
  // While a two-view pair is sought or held the first keyframe stays: the random start it
  // would be compared with, or replaced by, lives in that keyframe.
  const bool start_pending = bootstrap_ || pending_pair_;
  const bool view_degrades = tracked.stats.usage < options_.min_keyframe_usage ||
                             tracked.stats.good_ratio < options_.min_keyframe_good_ratio;
  const bool want_keyframe = !start_pending &&
                             frames_in_keyframe_ >= options_.min_frames_per_keyframe &&
                             (view_degrades || relative_distance > options_.keyframe_distance);
  if (tracked.status == TrackingStatus::kOk && relative_distance > options_.min_update_baseline) {
    // Only once initialised: the start's keyframe and its selection stay as they were.
    const SE3d T_kf_update = initialised_at_frame_ < 0
                                 ? tracked.T_kf_frame
                                 : update_direction_.Refine(map_->KeyframePtr()->Id(), image,
                                                            tracked.T_kf_frame, relative_distance);
    const StereoFrame stereo{frame.get(), T_kf_update.Inverse(), tracked.affine.Gain(),
                             tracked.affine.b, static_cast<float>(1.0 - tracked.stats.good_ratio)};
    depth_filter_.Update(map_.get(), stereo);
    ++depth_updates_;
    if (!want_keyframe) RebuildReference();
  }
  if (initialised_at_frame_ < 0) {
    BufferInitialFrame(frame, tracked.T_kf_frame);
    if (depth_updates_ >= options_.initialization_updates || want_keyframe) {
      if (want_keyframe) RebuildReference();
      result->revised = FinishInitialisation();
    }
  }
  if (want_keyframe) {  // ok or poor: a degrading view is the reason to switch
    InverseDepthMap next = depth_filter_.Propagate(*map_, frame, tracked.T_kf_frame.Inverse(),
                                                   tracked.affine.Gain(), tracked.affine.b);
    const float s = depth_filter_.NormalizeScale(&next);
    // Normalising multiplies idepth by s, so a point's new-keyframe coordinates become
    // p' = p / s; the keyframe-to-world similarity absorbs it: S_w_new = S_w_c * Sim3(s).
    const Sim3d S_w_c = CurrentKeyframePose() * Sim3d(tracked.T_kf_frame);
    const SE3d velocity(T_prev_last_.Rotation(), T_prev_last_.Translation() / s);
    StartKeyframe(frame, S_w_c * Sim3d(s, SO3d(), Eigen::Vector3d::Zero()), std::move(next),
                  result);
    SetPose(result, SE3d());  // the frame is the new keyframe
    update_direction_.SetKeyframe(frame->Id(), image);
    T_prev_last_ = velocity;  // constant-velocity guess for the next frame, new keyframe units
    affine_ = AffineBrightness{};
    result->is_keyframe = true;
  }
  result->mapping_ms = MillisecondsSince(start);
}

std::optional<TrackingResult> System::TrackRecentKeyframes(const Frame& frame,
                                                           FrameResult* result) {
  const Sim3d S_w_last = CurrentKeyframePose() * Sim3d(T_kf_last_);
  for (auto it = recent_.begin(); it != recent_.end(); ++it) {
    // Two starts, each tracked on its own (the tracker would prefer a start that sees few
    // points with small residuals): the last pose carried over through the similarities,
    // and the keyframe's own pose (the camera came back to where it was taken).
    const std::int64_t id = it->map->KeyframePtr()->Id();
    TrackingResult r =
        tracker_.Track(*it->reference, frame, {(graph_.Pose(id).Inverse() * S_w_last).RigidPart()},
                       AffineBrightness{});
    if (r.status != TrackingStatus::kOk) {
      r = tracker_.Track(*it->reference, frame, {SE3d()}, AffineBrightness{});
    }
    if (r.status != TrackingStatus::kOk) continue;
    // The found keyframe becomes current again (its depth is refined further and frozen
    // again when it is left); the current one is finished and takes its place among the
    // recent ones.
    FinishCurrentKeyframe(result);
    std::swap(map_, it->map);
    std::swap(reference_, it->reference);
    std::rotate(recent_.begin(), it, std::next(it));
    current_ = CurrentKeyframe{id, std::nullopt, Sim3d()};
    CompactOldKeyframes();
    update_direction_.Reset();  // its features are of the keyframe left behind
    T_kf_last_ = r.T_kf_frame;
    T_prev_last_ = SE3d();
    affine_ = r.affine;
    frames_in_keyframe_ = 1;
    return r;
  }
  return std::nullopt;
}

std::vector<Eigen::Vector3f> System::MapPoints() const {
  std::vector<Eigen::Vector3f> all = graph_.MapPoints(camera_);
  if (map_ && !graph_.Contains(current_.id)) {
    // The current keyframe's confirmed points, through its current pose.
    const Sim3d S_w_kf = CurrentKeyframePose();
    const PinholeCamera& K = map_->Keyframe().Camera(0);
    for (int y = 0; y < map_->Height(); ++y) {
      for (int x = 0; x < map_->Width(); ++x) {
        const std::size_t i = map_->Index(x, y);
        if (!map_->IsConfirmed(i)) continue;
        const Eigen::Vector3d p = K.Unproject(Eigen::Vector2d(x, y)) / map_->idepth_smoothed[i];
        all.push_back((S_w_kf * p).cast<float>());
      }
    }
  }
  return all;
}

std::vector<KeyframeRecord> System::Keyframes() const {
  std::vector<KeyframeRecord> records;
  for (const std::int64_t id : graph_.Ids()) {
    records.push_back({id, graph_.Get(id).timestamp, graph_.Pose(id)});
  }
  if (map_ && !graph_.Contains(current_.id)) {
    records.push_back({current_.id, map_->KeyframePtr()->Timestamp(), CurrentKeyframePose()});
  }
  return records;
}

std::vector<FramePose> System::Trajectory() const {
  std::vector<FramePose> poses;
  for (std::size_t k = 0; k < frame_poses_.size(); ++k) {
    const auto& anchor = frame_poses_[k];
    // A frame anchored to a keyframe of a map discarded by a restart has no pose any more.
    if (!anchor || (anchor->keyframe_id != current_.id && !graph_.Contains(anchor->keyframe_id)))
      continue;
    const Sim3d S_w_kf = KeyframePose(anchor->keyframe_id);
    poses.push_back({static_cast<std::int64_t>(k), frame_timestamps_[k],
                     (S_w_kf * Sim3d(anchor->T_kf_frame)).RigidPart()});
  }
  return poses;
}

}  // namespace parallax
