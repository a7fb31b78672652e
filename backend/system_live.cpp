// System, real-time mode, the caller's side (docs/realtime.md): live tracking against the
// published keyframe or the bridge at the frame that asked for the next one, the keyframe
// rule's verdict, and the answer handed on to the mapping thread.

#include "backend/live_tracker.hpp"
#include "backend/mapping_worker.hpp"
#include "backend/system.hpp"
#include "core/divergence.hpp"
#include "core/stopwatch.hpp"

namespace parallax {
namespace {

using Clock = StageClock;

}  // namespace

FrameResult System::ProcessLive(std::int64_t id, double timestamp, const ImageU8& image) {
  const auto call_start = Clock::now();
  LiveSnapshot snapshot = CatchUpWithStart(live_->Latest());
  if (!snapshot.usable && options_.realtime.answer_start_at_once) {
    return QueueStartFrame(id, timestamp, image);
  }
  std::shared_ptr<const Frame> frame;
  live_->arena.execute([&] {
    frame = std::make_shared<const Frame>(id, timestamp, camera_, image, options_.pyramid);
  });
  if (!snapshot.usable) return WaitForMapping(frame, image, std::nullopt, LiveTracking{});
  double paced_ms = 0.0;
  snapshot = PaceForRequestedKeyframe(std::move(snapshot), call_start, &paced_ms);
  live_->Follow(snapshot);
  const MotionState before = live_->tracker.State();
  LiveStep step = TrackKeyframeOrBridge(*frame, snapshot, before);
  live_->last_tracking_ms = step.tracking_ms;
  step.tracking_ms += paced_ms;
  if (step.tracked.status != TrackingStatus::kLost && !live_->tracker.Reacquires(step.tracked) &&
      live_->previous_lost) {
    // As System::TrackFrame: right after a loss only a confident match re-acquires.
    live_->tracker.SetState(before);
    step.tracked.status = TrackingStatus::kLost;
    step.overdue = false;
    step.keep = false;
  }
  if (step.overdue && live_->keyframe_request_frame >= 0) {
    // The keyframe this one needs was asked for by an earlier frame: wait until mapping
    // has made it (only that job, not the refinements or the backend behind it), then
    // track the frame again against it.
    const double waited_ms = WaitForRequestedKeyframe();
    const LiveSnapshot next = live_->Latest();
    if (next.usable && next.keyframe_id != snapshot.keyframe_id) {
      live_->tracker.SetState(before);
      snapshot = next;
      live_->Follow(snapshot);
      const double first_ms = step.tracking_ms;
      step = TrackLive(*frame, snapshot);
      step.tracking_ms += first_ms + waited_ms;
    }
  }
  if (step.tracked.status == TrackingStatus::kLost) {
    // Lost: the mapping thread tracks it again from the live tracker's motion, then tries
    // the recent keyframes and relocalisation with the whole map.
    return WaitForMapping(frame, image, std::nullopt,
                          LiveTracking{snapshot.keyframe_id, step.tracked, live_->tracker.State(),
                                       snapshot.generation});
  }
  if (step.overdue) {
    // Still past the rule with no new keyframe: this frame is mapped (and tracked again)
    // after the waiting jobs.
    FrameResult result = WaitForMapping(frame, image, std::nullopt, LiveTracking{});
    result.tracking_ms += step.tracking_ms;
    return result;
  }
  return AnswerLive(frame, image, snapshot, step);
}

System::LiveStep System::TrackOn(const TrackingReference& reference, const Frame& frame) {
  LiveStep step;
  const auto start = Clock::now();
  live_->arena.execute([&] {
    try {
      step.tracked = live_->tracker.Track(reference, frame);
    } catch (const NumericalDivergence& e) {
      // Lost, with the tracker's state as before: the mapping thread tries the frame again.
      step.tracked = DivergedTracking(e);
    }
  });
  step.tracking_ms = MillisecondsSince(start);
  return step;
}

System::LiveStep System::TrackLive(const Frame& frame, const LiveSnapshot& snapshot) {
  LiveStep step = TrackOn(*snapshot.reference, frame);
  if (step.tracked.status == TrackingStatus::kLost) return step;
  // The keyframe rule of MapFrame: a frame that wants a new keyframe is never skipped by
  // mapping (once per keyframe); tracking goes on against the current one meanwhile, which
  // still tracks (the rule fires well before the view is lost), and follows the new one
  // when it is published.
  JudgeKeyframeRule(snapshot, &step);
  return step;
}

System::LiveStep System::TrackKeyframeOrBridge(const Frame& frame, const LiveSnapshot& snapshot,
                                               const MotionState& before) {
  LiveBridge* bridge = PendingBridge(snapshot);
  if (bridge != nullptr && !bridge->engaged && PredictedOverdue(frame, snapshot)) {
    bridge->engaged = true;  // tracked once, on the bridge, rather than twice
  }
  if (bridge != nullptr && bridge->engaged) {
    LiveStep step = TrackOnBridge(frame, snapshot, *bridge);
    if (step.tracked.status != TrackingStatus::kLost) return step;
    // Lost on the bridge: the keyframe decides, as without a bridge.
    live_->tracker.SetState(before);
    const double bridge_ms = step.tracking_ms;
    step = TrackLive(frame, snapshot);
    step.tracking_ms += bridge_ms;
    return step;
  }
  LiveStep step = TrackLive(frame, snapshot);
  if (bridge == nullptr || !step.overdue) return step;
  // Overdue: the bridge from here on, instead of waiting for the keyframe.
  bridge->engaged = true;
  const MotionState on_keyframe = live_->tracker.State();
  live_->tracker.SetState(before);
  LiveStep bridged = TrackOnBridge(frame, snapshot, *bridge);
  bridged.tracking_ms += step.tracking_ms;
  if (bridged.tracked.status != TrackingStatus::kLost) return bridged;
  live_->tracker.SetState(on_keyframe);
  step.tracking_ms = bridged.tracking_ms;
  return step;
}

bool System::PredictedOverdue(const Frame& frame, const LiveSnapshot& snapshot) const {
  const SE3d T_kf_frame = live_->tracker.Predicted(frame.Timestamp());
  const double f = options_.realtime.keyframe_wait_factor;
  return options_.KeyframeDistance(snapshot.parallax, T_kf_frame.Translation()) >
             f * options_.keyframe_distance ||
         options_.TurnedPast(live_->tracker.State().frames_in_keyframe + 1,
                             SystemOptions::RotationDeg(T_kf_frame), f);
}

System::LiveStep System::TrackOnBridge(const Frame& frame, const LiveSnapshot& snapshot,
                                       const LiveBridge& bridge) {
  live_->tracker.SetState(bridge.ToBridge(live_->tracker.State()));
  LiveStep step = TrackOn(*bridge.reference, frame);
  live_->tracker.SetState(bridge.FromBridge(live_->tracker.State()));
  if (step.tracked.status != TrackingStatus::kOk) {
    // Only a confident match on the bridge answers the frame: a bridge holds the keyframe's
    // depth unrefined by the frames past it, and a poor match on it can be a wrong minimum
    // on a fast turn (docs/benchmarks.md, "The bridge's failures traced"); the keyframe
    // decides instead.
    step.tracked.status = TrackingStatus::kLost;
    return step;
  }
  ++live_->tracked_on_bridge;
  // The keyframe was asked for already: the rule only tells whether the frame has gone so
  // far past the bridge's frame that it must wait for the keyframe.
  JudgeKeyframeRule(snapshot, &step);
  step.keep = false;
  step.tracked = bridge.FromBridge(step.tracked);
  return step;
}

LiveBridge* System::PendingBridge(const LiveSnapshot& snapshot) {
  std::optional<LiveBridge>& bridge = live_->bridge;
  if (!bridge || live_->keyframe_requested_in != snapshot.keyframe_id ||
      !bridge->Serves(snapshot) || bridge->frame_id != live_->keyframe_request_frame ||
      snapshot.keyframe_updates <
          static_cast<std::uint32_t>(options_.realtime.bridge_min_keyframe_updates)) {
    return nullptr;
  }
  return &*bridge;
}

void System::JudgeKeyframeRule(const LiveSnapshot& snapshot, LiveStep* step) const {
  const TrackingResult& t = step->tracked;
  const double relative_distance =
      options_.KeyframeDistance(snapshot.parallax, t.T_kf_frame.Translation());
  const double rotation_deg = SystemOptions::RotationDeg(t.T_kf_frame);
  const int frames_in_keyframe = live_->tracker.State().frames_in_keyframe;
  const bool wants_keyframe =
      snapshot.initialised &&
      options_.WantsKeyframe(frames_in_keyframe, relative_distance, rotation_deg, t.stats);
  step->keep = wants_keyframe && live_->keyframe_requested_in != snapshot.keyframe_id;
  const double f = options_.realtime.keyframe_wait_factor;
  step->overdue = wants_keyframe && !step->keep &&
                  (relative_distance > f * options_.keyframe_distance ||
                   options_.TurnedPast(frames_in_keyframe, rotation_deg, f) ||
                   t.stats.usage * f < options_.min_keyframe_usage ||
                   t.stats.good_ratio * f < options_.min_keyframe_good_ratio);
}

double System::WaitForRequestedKeyframe() {
  const auto start = Clock::now();
  worker_->WaitFor(live_->keyframe_request_frame);
  ++live_->waited_for_keyframe;
  return MillisecondsSince(start);
}

LiveSnapshot System::PaceForRequestedKeyframe(LiveSnapshot snapshot,
                                              StageClock::time_point call_start,
                                              double* waited_ms) {
  const double budget_ms = options_.realtime.keyframe_pacing_ms - live_->last_tracking_ms;
  if (budget_ms <= 0.0 || live_->keyframe_request_frame < 0 ||
      live_->keyframe_requested_in != snapshot.keyframe_id) {
    return snapshot;
  }
  const auto deadline = call_start + std::chrono::duration_cast<StageClock::duration>(
                                         std::chrono::duration<double, std::milli>(budget_ms));
  const auto start = Clock::now();
  if (deadline <= start) return snapshot;
  const bool done = worker_->WaitFor(live_->keyframe_request_frame, deadline);
  *waited_ms += MillisecondsSince(start);
  LiveSnapshot next = done ? live_->Latest() : LiveSnapshot{};
  const bool changed = next.usable && next.keyframe_id != snapshot.keyframe_id;
  // A request mapping answered without a keyframe (its propagated map diverged, or the
  // request was made on a keyframe mapping had left) paced nothing.
  if (!done || changed) ++live_->paced_for_keyframe;
  return changed ? next : snapshot;
}

FrameResult System::AnswerLive(const std::shared_ptr<const Frame>& frame, const ImageU8& image,
                               const LiveSnapshot& snapshot, const LiveStep& step) {
  if (step.keep) {
    live_->keyframe_requested_in = snapshot.keyframe_id;
    live_->keyframe_request_frame = frame->Id();
    live_->keyframe_request_sequence = live_->tracked_live;
    live_->bridge.reset();
    if (options_.realtime.bridge_keyframe_requests && step.tracked.status == TrackingStatus::kOk) {
      const TrackingResult& t = step.tracked;
      live_->bridge =
          LiveBridge{snapshot.keyframe_id,
                     snapshot.generation,
                     frame->Id(),
                     t.T_kf_frame,
                     t.affine,
                     std::make_shared<const TrackingReference>(snapshot.reference->MovedTo(
                         frame, t.T_kf_frame.Inverse(), t.affine.Gain(), t.affine.b))};
    }
  }
  FrameResult result;
  result.status = step.tracked.status;
  result.stats = step.tracked.stats;
  result.tracking_ms = step.tracking_ms;
  result.initialising = !snapshot.initialised;
  result.anchor = AnchoredPose{snapshot.keyframe_id, step.tracked.T_kf_frame};
  result.T_w_c = (snapshot.S_w_kf * Sim3d(step.tracked.T_kf_frame)).RigidPart();
  Record(frame->Id(), result);
  LiveTracking live{snapshot.keyframe_id, step.tracked, live_->tracker.State(),
                    snapshot.generation};
  worker_->Offer(MappingJob{frame, image, std::move(live), false, step.keep, LiveTracking{},
                            live_->previous_lost},
                 !snapshot.initialised);
  ++live_->tracked_live;
  TakePendingEvents(&result);
  return result;
}

}  // namespace parallax
