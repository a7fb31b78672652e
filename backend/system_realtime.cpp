// System, real-time mode (docs/realtime.md): starting and ending the threads, the mapping
// thread's jobs, the backend's batches and the snapshot live tracking reads (the caller's
// side is system_live.cpp).

#include <chrono>
#include <opencv2/core/utility.hpp>

#include "backend/backend_worker.hpp"
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
  CheckOption(waited_mapping_threads >= 1, "RealtimeOptions", "waited_mapping_threads",
              "must be >= 1");
  CheckOption(keyframe_mapping_threads >= 1, "RealtimeOptions", "keyframe_mapping_threads",
              "must be >= 1");
  CheckOption(opencv_threads >= 1, "RealtimeOptions", "opencv_threads", "must be >= 1");
  CheckOption(keyframe_wait_factor >= 1.0, "RealtimeOptions", "keyframe_wait_factor",
              "must be >= 1");
  CheckOption(keyframe_pacing_ms >= 0.0, "RealtimeOptions", "keyframe_pacing_ms", "must be >= 0");
  CheckOption(bridge_min_keyframe_updates >= 0, "RealtimeOptions", "bridge_min_keyframe_updates",
              "must be >= 0");
  CheckOption(snapshot_keyframe_poses >= 0, "RealtimeOptions", "snapshot_keyframe_poses",
              "must be >= 0");
  CheckOption(backend_threads >= 1, "RealtimeOptions", "backend_threads", "must be >= 1");
  CheckOption(backend_drain_threads >= 1, "RealtimeOptions", "backend_drain_threads",
              "must be >= 1");
  CheckOption(backend_nice >= 0 && backend_nice <= 19, "RealtimeOptions", "backend_nice",
              "must be in [0, 19]");
  CheckOption(max_queued_start_frames >= 1, "RealtimeOptions", "max_queued_start_frames",
              "must be >= 1");
  CheckOption(catch_up_refinements >= 0, "RealtimeOptions", "catch_up_refinements", "must be >= 0");
}

void System::StartRealtime() {
  cv::setNumThreads(options_.realtime.opencv_threads);
  live_ = std::make_unique<LiveTracker>(options_.tracker, options_.realtime.tracking_threads);
  backend_worker_ = std::make_unique<BackendWorker>(
      [this] { RunBackendBatch(); }, options_.realtime.backend_threads,
      options_.realtime.backend_drain_threads, options_.realtime.backend_nice);
  worker_ = std::make_unique<MappingWorker>(
      [this](const MappingJob& job) { return MapJob(job); },
      static_cast<std::size_t>(options_.realtime.max_pending_frames),
      options_.realtime.mapping_threads, options_.realtime.waited_mapping_threads,
      options_.realtime.keyframe_mapping_threads);
}

System::~System() { StopMapping(); }

std::vector<SystemEvent> System::FinishMapping() {
  FrameResult last;
  if (worker_) {
    worker_->Drain();  // mapping first: it may finish keyframes for the backend
    backend_worker_->Drain();
  }
  {
    const std::lock_guard<std::mutex> engine(engine_mutex_);
    // Finishing it again later (frames given after this) repeats nothing: its image is in
    // the place database and its edges exist. After StopMapping the backend is gone.
    if (start_ == StartState::kInitialised && !mapping_stopped_) FinishCurrentKeyframe(&last);
  }
  if (worker_) backend_worker_->Drain();
  const std::lock_guard<std::mutex> pending(poses_mutex_);
  last.events.insert(last.events.begin(), pending_events_.begin(), pending_events_.end());
  pending_events_.clear();
  return last.events;
}

void System::StopMapping() {
  if (!worker_) return;
  worker_->Stop();
  backend_worker_->Stop();
  // Keyframes the backend never reached keep the chain tracking made (no keyframe made is
  // lost; they are only not optimised).
  const std::lock_guard<std::mutex> lock(engine_mutex_);
  mapping_stopped_ = true;
  AddChainEdges(&graph_, std::exchange(backend_pending_, {}));
}

void System::AddChainEdges(KeyframeGraph* graph,
                           const std::vector<FinishedKeyframe>& keyframes) const {
  for (const FinishedKeyframe& k : keyframes) {
    if (k.parent && graph->Contains(*k.parent) && graph->Contains(k.id) &&
        !graph->HasEdge(*k.parent, k.id)) {
      graph->AddEdge(
          PoseGraphEdge{*k.parent, k.id, k.S_parent_kf, chain_information_, EdgeKind::kOdometry});
    }
  }
}

RealtimeStats System::Realtime() const {
  RealtimeStats stats;
  if (!live_) return stats;
  stats.frames_tracked_live = live_->tracked_live;
  stats.frames_mapped_waiting = live_->mapped_waiting;
  stats.frames_queued_for_start = live_->queued_for_start;
  stats.frames_waiting_for_keyframe = live_->waited_for_keyframe;
  stats.frames_paced_for_keyframe = live_->paced_for_keyframe;
  stats.frames_tracked_on_bridge = live_->tracked_on_bridge;
  stats.frames_skipped_by_mapping = worker_->Skipped() + live_->caught_up.load();
  return stats;
}

void System::TakePendingEvents(FrameResult* result) {
  const std::lock_guard<std::mutex> lock(poses_mutex_);
  result->events.insert(result->events.begin(), pending_events_.begin(), pending_events_.end());
  pending_events_.clear();
}

FrameResult System::WaitForMapping(const std::shared_ptr<const Frame>& frame, const ImageU8& image,
                                   std::optional<LiveTracking> live, LiveTracking hint) {
  MappingJob job{frame, image, std::move(live), true, false, std::move(hint), live_->previous_lost};
  FrameResult result = worker_->Run(std::move(job));
  ++live_->mapped_waiting;
  live_->Adopt(live_->Latest());
  TakePendingEvents(&result);
  return result;
}

FrameResult System::QueueStartFrame(std::int64_t id, double timestamp, const ImageU8& image) {
  // The start's frames are mapped in order as in the deterministic mode, by the mapping
  // thread (with both cores: the caller is idle), which also builds their pyramids: the
  // first touch of a buffered frame's new memory costs about 17 ms at 640x480 here
  // (docs/realtime.md). The caller waits only when max_queued_start_frames wait already (a
  // recording fed faster than the start maps).
  MappingJob job{nullptr, image, std::nullopt, false, false, LiveTracking{}, std::nullopt};
  job.unbuilt_id = id;
  job.unbuilt_timestamp = timestamp;
  worker_->Queue(std::move(job),
                 static_cast<std::size_t>(options_.realtime.max_queued_start_frames));
  live_->last_queued_start = id;
  ++live_->queued_for_start;
  FrameResult result;
  result.initialising = true;
  result.answered_before_mapping = true;
  TakePendingEvents(&result);
  return result;
}

LiveSnapshot System::CatchUpWithStart(LiveSnapshot snapshot) {
  // The start completed behind the caller: the frames queued after the one that completed
  // it are mapped in order first, once (the caller waits), so that live tracking continues
  // from the mapping thread's newest frame rather than from a pose frames behind.
  if (!snapshot.usable || live_->last_queued_start < 0) return snapshot;
  worker_->WaitFor(std::exchange(live_->last_queued_start, -1));
  snapshot = live_->Latest();
  live_->Adopt(snapshot);
  return snapshot;
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
    MapFrame(job.frame, job.image, job.live->tracked, &result, DepthWork::kRefine, job.keep);
    last_posed_timestamp_ = job.frame->Timestamp();
    previous_frame_lost_ = false;
    Record(job.frame->Id(), result);
  } else {
    if (job.hint.keyframe_id >= 0 && job.hint.keyframe_id == current_.id &&
        job.hint.generation == map_generation_ && start_ == StartState::kInitialised) {
      tracker_.SetState(job.hint.motion);
    }
    if (job.previous_lost) previous_frame_lost_ = *job.previous_lost;
    const std::shared_ptr<const Frame> frame =
        job.frame ? job.frame
                  : std::make_shared<const Frame>(job.unbuilt_id, job.unbuilt_timestamp, camera_,
                                                  job.image, options_.pyramid);
    // A start frame with newer ones queued behind it, after the start completed (the
    // catch-up): tracked, and a keyframe when the rule asks, but depth is refined only
    // while the keyframe is young; the newest refines (docs/realtime.md, "The catch-up").
    const bool catch_up =
        job.caller_idle && job.newer_waiting && start_ == StartState::kInitialised;
    result = ProcessInOrder(frame, job.image,
                            catch_up ? DepthWork::kRefineYoungKeyframe : DepthWork::kRefine);
    // A frame the caller already has a pose for keeps it when tracking it again here failed.
    if (!result.T_w_c && job.live && !job.caller_waits) {
      FrameResult live;
      live.anchor = AnchoredPose{job.live->keyframe_id, job.live->tracked.T_kf_frame};
      Record(job.FrameId(), live);
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

void System::RunBackendBatch() {
  // Inputs under the engine lock: the keyframes waiting and a copy of the graph (keyframes
  // are shared and immutable: the copy is poses, edges and pointers).
  std::unique_lock<std::mutex> engine(engine_mutex_);
  if (backend_pending_.empty()) return;
  backend_running_ = std::exchange(backend_pending_, {});
  KeyframeGraph work = graph_;
  const std::size_t edges_before = work.Poses().Edges().size();
  const std::int64_t frame_id = result_frame_id_;
  engine.unlock();
  // The work, while tracking and mapping go on.
  BackendStats stats;
  std::vector<SystemEvent> events;
  for (const FinishedKeyframe& finished : backend_running_) {
    backend_worker_->RunStep([&] { RunBackendOn(&work, finished, frame_id, &stats, &events); });
  }
  const Matrix7d chain_information = backend_.FallbackInformation();
  // The result, under the lock again: keyframes made meanwhile move with their map.
  engine.lock();
  graph_.AdoptOptimised(work, edges_before);
  backend_running_.clear();
  backend_stats_.Add(stats);
  chain_information_ = chain_information;
  FollowMerges(events);
  PublishLive();  // keyframe poses moved
  const std::lock_guard<std::mutex> pending(poses_mutex_);
  pending_events_.insert(pending_events_.end(), events.begin(), events.end());
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
    s.parallax = options_.KeyframeMoments(mapper_.Map());
    s.keyframe_updates = mapper_.Map().updates;
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
