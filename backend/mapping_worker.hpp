#pragma once
// The mapping thread of the real-time mode (docs/realtime.md): frames tracked live on the
// caller's thread come here to refine depth and make keyframes. A bounded
// queue with condition variables; when mapping falls behind, the oldest waiting refinement
// is skipped for the newest. Jobs the caller waits for are never skipped.

#include <tbb/task_arena.h>

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <exception>
#include <functional>
#include <future>
#include <memory>
#include <mutex>
#include <optional>
#include <thread>

#include "backend/frame_tracker.hpp"
#include "backend/system.hpp"
#include "core/frame.hpp"
#include "core/image.hpp"

namespace parallax {

/// What the live tracker found for a frame, in the keyframe it tracked against.
struct LiveTracking {
  std::int64_t keyframe_id = -1;
  TrackingResult tracked;
  MotionState motion;            ///< the live tracker's state after this frame
  std::uint64_t generation = 0;  ///< of the map it tracked against (System::map_generation_)
};

/// A frame for the mapping thread; `live` is empty when the mapping thread must track it
/// itself (the start, a lost frame).
struct MappingJob {
  /// Empty: the mapping thread builds it from `image`, `unbuilt_id` and `unbuilt_timestamp`
  /// (a start frame: its pyramid's first touch of new memory costs the caller nothing).
  std::shared_ptr<const Frame> frame;
  ImageU8 image;  ///< the undistorted 8-bit image
  std::optional<LiveTracking> live;
  bool caller_waits = false;  ///< its result goes back to the caller (not to pending events)
  bool keep = false;          ///< never skipped (it asks for a new keyframe)
  /// A frame the live tracker lost: its motion state after its last good frame, which is
  /// newer than the mapping thread's when mapping skipped frames (keyframe_id -1: none).
  LiveTracking hint;
  /// The caller's previous frame got no pose (System: a "poor" tracking right after a loss
  /// is not trusted); empty for a frame the caller did not try to track (the start): the
  /// mapping thread's own record of its previous frame holds.
  std::optional<bool> previous_lost;
  /// Queued by Queue(): the caller's thread is idle meanwhile (the start answered at once),
  /// so the job gets the waited jobs' wider arena.
  bool caller_idle = false;
  /// Set by the mapping thread when it takes the job: newer jobs were queued behind it.
  bool newer_waiting = false;
  std::int64_t unbuilt_id = -1;
  double unbuilt_timestamp = 0.0;

  std::int64_t FrameId() const { return frame ? frame->Id() : unbuilt_id; }
};

class MappingWorker {
 public:
  using Process = std::function<FrameResult(const MappingJob&)>;

  /// `process` maps a job. `max_pending`: refinement jobs that may wait (>= 1); `threads`:
  /// the TBB concurrency of the thread's arena; `waited_threads`: that of the jobs the caller
  /// waits for (Run) or is idle during (Queue); `keyframe_threads`: that of keyframe
  /// requests offered while the caller tracks (`keep`), which it may soon wait for. The
  /// thread starts here.
  MappingWorker(Process process, std::size_t max_pending, int threads, int waited_threads,
                int keyframe_threads);
  /// Stop().
  ~MappingWorker();
  MappingWorker(const MappingWorker&) = delete;
  MappingWorker& operator=(const MappingWorker&) = delete;

  /// Queues a refinement; when max_pending already wait, the oldest of them is skipped, or,
  /// with `wait_for_room`, the call waits until mapping takes one (the start: its depth
  /// converges only from the frames it maps). Rethrows (once) an exception an earlier
  /// refinement threw.
  void Offer(MappingJob job, bool wait_for_room = false);
  /// Queues a job that is never skipped and runs with the waited jobs' wider arena while
  /// the caller's thread is idle (the start, answered at once); waits while `max_queued`
  /// (>= 1) such jobs are waiting. Rethrows as Offer does.
  void Queue(MappingJob job, std::size_t max_queued);
  /// Queues a job behind the waiting ones and returns its result (rethrowing its exception).
  FrameResult Run(MappingJob job);
  /// Returns once the job of frame `frame_id` (or a later frame's) is done, or the worker
  /// stopped; rethrows as Offer does. Precondition: that frame's job was queued and is
  /// never skipped (`keep`).
  void WaitFor(std::int64_t frame_id);
  /// As WaitFor, but returns at `deadline` at the latest: whether that job is done.
  bool WaitFor(std::int64_t frame_id, std::chrono::steady_clock::time_point deadline);
  /// Returns once every queued job is done (rethrows as Offer does).
  void Drain();
  /// Drops the waiting jobs, lets the running one finish and joins the thread. Idempotent.
  void Stop();
  /// Refinements skipped because mapping was behind.
  std::int64_t Skipped() const;

 private:
  struct Entry {
    MappingJob job;
    std::shared_ptr<std::promise<FrameResult>> done;  ///< set for jobs the caller waits for
  };
  static bool Skippable(const Entry& e) { return !e.done && !e.job.keep; }
  void Loop();
  void RethrowFailure();  // precondition: mutex_ held
  /// The job of `frame_id` (or a later frame's) is done, or the worker stopped or failed
  /// (precondition: mutex_ held).
  bool DoneOrEnded(std::int64_t frame_id) const {
    return done_through_ >= frame_id || stopping_ || failure_;
  }

  Process process_;
  std::size_t max_pending_;
  tbb::task_arena arena_;
  tbb::task_arena waited_arena_;
  tbb::task_arena keyframe_arena_;
  mutable std::mutex mutex_;
  std::condition_variable wake_;  ///< a job was queued, or stop
  std::condition_variable idle_;  ///< a job finished
  std::deque<Entry> queue_;
  bool busy_ = false;
  bool stopping_ = false;
  std::exception_ptr failure_;
  std::int64_t skipped_ = 0;
  std::int64_t done_through_ = -1;  ///< frame id of the newest finished job
  std::thread thread_;              ///< last: started when everything above exists
};

}  // namespace parallax
