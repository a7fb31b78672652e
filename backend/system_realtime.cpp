// System, real-time mode (docs/realtime.md): tracking on the caller's thread against the
// keyframe the mapping thread last published; everything else on the mapping thread.

#include <chrono>
#include <opencv2/core/utility.hpp>

#include "backend/live_tracker.hpp"
#include "backend/mapping_worker.hpp"
#include "backend/system.hpp"
#include "core/check.hpp"
#include "core/stopwatch.hpp"

namespace parallax {
namespace {

using Clock = StageClock;

}  // namespace

void RealtimeOptions::Check() const {
  CheckOption(max_pending_frames >= 1, "RealtimeOptions", "max_pending_frames", "must be >= 1");
  CheckOption(tracking_threads >= 1, "RealtimeOptions", "tracking_threads", "must be >= 1");
  CheckOption(mapping_threads >= 1, "RealtimeOptions", "mapping_threads", "must be >= 1");
  CheckOption(opencv_threads >= 1, "RealtimeOptions", "opencv_threads", "must be >= 1");
  CheckOption(keyframe_wait_factor >= 1.0, "RealtimeOptions", "keyframe_wait_factor",
              "must be >= 1");
  CheckOption(snapshot_keyframe_poses >= 0, "RealtimeOptions", "snapshot_keyframe_poses",
              "must be >= 0");
}

void System::StartRealtime() {
  cv::setNumThreads(options_.realtime.opencv_threads);
  live_ = std::make_unique<LiveTracker>(options_.tracker, options_.realtime.tracking_threads);
  worker_ = std::make_unique<MappingWorker>(
      [this](const MappingJob& job) { return MapJob(job); }, [this] { RunDeferredBackend(); },
      static_cast<std::size_t>(options_.realtime.max_pending_frames),
      options_.realtime.mapping_threads);
}

System::~System() {
  if (worker_) worker_->Stop();
}

void System::FinishMapping() {
  if (worker_) worker_->Drain();
}

void System::StopMapping() {
  if (worker_) worker_->Stop();
}

RealtimeStats System::Realtime() const {
  RealtimeStats stats;
  if (!live_) return stats;
  stats.frames_tracked_live = live_->tracked_live;
  stats.frames_mapped_waiting = live_->mapped_waiting;
  stats.frames_skipped_by_mapping = worker_->Skipped();
  return stats;
}

void System::TakePendingEvents(FrameResult* result) {
  const std::lock_guard<std::mutex> lock(poses_mutex_);
  result->events.insert(result->events.begin(), pending_events_.begin(), pending_events_.end());
  pending_events_.clear();
}

FrameResult System::WaitForMapping(const std::shared_ptr<const Frame>& frame, const ImageU8& image,
                                   std::optional<LiveTracking> live, LiveTracking hint) {
  MappingJob job{frame, image, std::move(live), true, false, std::move(hint)};
  FrameResult result = worker_->Run(std::move(job));
  ++live_->mapped_waiting;
  live_->Adopt(live_->Latest());
  TakePendingEvents(&result);
  return result;
}

FrameResult System::ProcessLive(std::int64_t id, double timestamp, const ImageU8& image) {
  std::shared_ptr<const Frame> frame;
  live_->arena.execute([&] {
    frame = std::make_shared<const Frame>(id, timestamp, camera_, image, options_.pyramid);
  });
  const LiveSnapshot snapshot = live_->Latest();
  if (!snapshot.usable) return WaitForMapping(frame, image, std::nullopt, LiveTracking{});
  live_->Follow(snapshot);
  const auto start = Clock::now();
  TrackingResult tracked;
  live_->arena.execute([&] { tracked = live_->tracker.Track(*snapshot.reference, *frame); });
  const double tracking_ms = MillisecondsSince(start);
  // Lost: the mapping thread tracks it again from the live tracker's motion, then tries the
  // recent keyframes and relocalisation with the whole map.
  if (tracked.status == TrackingStatus::kLost) {
    return WaitForMapping(
        frame, image, std::nullopt,
        LiveTracking{snapshot.keyframe_id, tracked, live_->tracker.State(), snapshot.generation});
  }
  LiveTracking live{snapshot.keyframe_id, tracked, live_->tracker.State(), snapshot.generation};
  // The keyframe rule of MapFrame: a frame that wants a new keyframe is never skipped by
  // mapping (once per keyframe); tracking goes on against the current one meanwhile, which
  // still tracks (the rule fires well before the view is lost), and follows the new one
  // when it is published.
  const double relative_distance = tracked.T_kf_frame.Translation().norm() * snapshot.mean_idepth;
  const bool view_degrades = tracked.stats.usage < options_.min_keyframe_usage ||
                             tracked.stats.good_ratio < options_.min_keyframe_good_ratio;
  const bool wants_keyframe = snapshot.initialised &&
                              live.motion.frames_in_keyframe >= options_.min_frames_per_keyframe &&
                              (view_degrades || relative_distance > options_.keyframe_distance);
  const bool keep = wants_keyframe && live_->keyframe_requested_in != snapshot.keyframe_id;
  if (keep) live_->keyframe_requested_in = snapshot.keyframe_id;
  const double f = options_.realtime.keyframe_wait_factor;
  if (wants_keyframe && !keep &&
      (relative_distance > f * options_.keyframe_distance ||
       tracked.stats.usage * f < options_.min_keyframe_usage ||
       tracked.stats.good_ratio * f < options_.min_keyframe_good_ratio)) {
    // The requested keyframe is overdue: this frame is mapped (and tracked again) after it.
    FrameResult result = WaitForMapping(frame, image, std::nullopt, LiveTracking{});
    result.tracking_ms += tracking_ms;
    return result;
  }
  FrameResult result;
  result.status = tracked.status;
  result.stats = tracked.stats;
  result.tracking_ms = tracking_ms;
  result.initialising = !snapshot.initialised;
  result.anchor = AnchoredPose{snapshot.keyframe_id, tracked.T_kf_frame};
  result.T_w_c = (snapshot.S_w_kf * Sim3d(tracked.T_kf_frame)).RigidPart();
  Record(frame->Id(), result);
  worker_->Offer(MappingJob{frame, image, std::move(live), false, keep, LiveTracking{}},
                 !snapshot.initialised);
  ++live_->tracked_live;
  TakePendingEvents(&result);
  return result;
}

FrameResult System::MapJob(const MappingJob& job) {
  const std::lock_guard<std::mutex> lock(engine_mutex_);
  const auto start = Clock::now();
  FrameResult result;
  const bool same_keyframe = job.live && start_ == StartState::kInitialised && mapper_.HasMap() &&
                             job.live->keyframe_id == current_.id &&
                             job.live->generation == map_generation_;
  if (same_keyframe) {
    // The live tracker's result is this thread's: no second tracking of the frame.
    result_frame_id_ = job.frame->Id();
    tracker_.SetState(job.live->motion);
    result.status = job.live->tracked.status;
    result.stats = job.live->tracked.stats;
    SetPose(&result, job.live->tracked.T_kf_frame);
    MapFrame(job.frame, job.image, job.live->tracked, &result);
    last_posed_timestamp_ = job.frame->Timestamp();
    Record(job.frame->Id(), result);
  } else {
    if (job.hint.keyframe_id >= 0 && job.hint.keyframe_id == current_.id &&
        job.hint.generation == map_generation_ && start_ == StartState::kInitialised) {
      tracker_.SetState(job.hint.motion);
    }
    result = ProcessInOrder(job.frame, job.image);
    // A frame the caller already has a pose for keeps it when tracking it again here failed.
    if (!result.T_w_c && job.live && !job.caller_waits) {
      FrameResult live;
      live.anchor = AnchoredPose{job.live->keyframe_id, job.live->tracked.T_kf_frame};
      Record(job.frame->Id(), live);
    }
  }
  result.mapping_ms = MillisecondsSince(start);
  PublishLive();
  if (!job.caller_waits) {
    const std::lock_guard<std::mutex> events(poses_mutex_);
    pending_events_.insert(pending_events_.end(), result.events.begin(), result.events.end());
  }
  return result;
}

void System::RunDeferredBackend() {
  const std::lock_guard<std::mutex> lock(engine_mutex_);
  if (deferred_backend_.empty()) return;
  FrameResult result;
  for (const FinishedKeyframe& finished : std::exchange(deferred_backend_, {})) {
    RunBackend(finished, &result);
  }
  PublishLive();  // keyframe poses moved
  const std::lock_guard<std::mutex> events(poses_mutex_);
  pending_events_.insert(pending_events_.end(), result.events.begin(), result.events.end());
}

void System::PublishLive() {
  LiveSnapshot s;
  // The start runs on the mapping thread with the caller waiting, frame by frame as in the
  // deterministic mode: its second tracking revises the poses of exactly the frames it saw,
  // and it may replace or rescale the map (measured: live tracking during the start left
  // the TUM clip at 31 mm against 6 mm).
  s.initialised = start_ == StartState::kInitialised;
  s.usable = s.initialised && mapper_.HasMap();
  s.motion = tracker_.State();
  s.generation = map_generation_;
  if (s.usable) {
    s.keyframe_id = current_.id;
    s.reference = mapper_.Reference();
    s.S_w_kf = CurrentKeyframePose();
    s.mean_idepth = mapper_.Map().MeanSmoothedIdepth();
    if (s.keyframe_id != live_->published_keyframe_id) {
      live_->published_previous_id = live_->published_keyframe_id;
      live_->published_keyframe_id = s.keyframe_id;
    }
    const std::int64_t previous = live_->published_previous_id;
    const std::vector<std::int64_t> ids = graph_.Ids();
    const auto recent = static_cast<std::size_t>(options_.realtime.snapshot_keyframe_poses);
    for (std::size_t k = ids.size() > recent ? ids.size() - recent : 0; k < ids.size(); ++k) {
      s.recent_poses.emplace_back(ids[k], graph_.Pose(ids[k]));
    }
    if (previous >= 0 && graph_.Contains(previous)) {
      s.previous_keyframe_id = previous;
      s.S_kf_previous = s.S_w_kf.Inverse() * graph_.Pose(previous);
    }
  }
  const std::lock_guard<std::mutex> lock(live_->mutex);
  live_->snapshot = std::move(s);
}

}  // namespace parallax
