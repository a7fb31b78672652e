#include "backend/mapping_worker.hpp"

#include <algorithm>

#include "backend/arena_width.hpp"
#include "core/check.hpp"
#include "core/thread_name.hpp"

namespace parallax {

MappingWorker::MappingWorker(Process process, std::size_t max_pending, int threads,
                             int waited_threads, int keyframe_threads)
    : process_(std::move(process)),
      max_pending_(max_pending),
      arena_(ArenaWidth(threads)),
      waited_arena_(ArenaWidth(waited_threads)),
      keyframe_arena_(ArenaWidth(keyframe_threads)) {
  CheckArgument(max_pending_ >= 1, "MappingWorker: max_pending must be >= 1");
  thread_ = std::thread([this] { Loop(); });
}

MappingWorker::~MappingWorker() { Stop(); }

void MappingWorker::RethrowFailure() {
  if (failure_) std::rethrow_exception(std::exchange(failure_, nullptr));
}

void MappingWorker::Offer(MappingJob job, bool wait_for_room) {
  {
    std::unique_lock<std::mutex> lock(mutex_);
    const auto refinements = [this] {
      return static_cast<std::size_t>(
          std::count_if(queue_.begin(), queue_.end(), [](const Entry& e) { return Skippable(e); }));
    };
    if (wait_for_room) {
      idle_.wait(lock, [&] { return refinements() < max_pending_ || stopping_ || failure_; });
    }
    RethrowFailure();
    CheckState(!stopping_, "MappingWorker::Offer: stopped");
    if (job.keep) {
      // The new keyframe is made next: refinements of the old one are worth less than the
      // time the tracker may have to wait for it.
      const auto waiting =
          std::remove_if(queue_.begin(), queue_.end(), [](const Entry& e) { return Skippable(e); });
      skipped_ += std::distance(waiting, queue_.end());
      queue_.erase(waiting, queue_.end());
    } else if (refinements() >= max_pending_) {
      // The newest frame refines better than an older one mapping has not reached.
      queue_.erase(
          std::find_if(queue_.begin(), queue_.end(), [](const Entry& e) { return Skippable(e); }));
      ++skipped_;
    }
    queue_.push_back({std::move(job), nullptr});
  }
  wake_.notify_one();
}

void MappingWorker::Queue(MappingJob job, std::size_t max_queued) {
  job.keep = true;  // never skipped
  job.caller_idle = true;
  {
    std::unique_lock<std::mutex> lock(mutex_);
    const auto queued = [this] {
      return static_cast<std::size_t>(std::count_if(
          queue_.begin(), queue_.end(), [](const Entry& e) { return e.job.caller_idle; }));
    };
    idle_.wait(lock, [&] { return queued() < max_queued || stopping_ || failure_; });
    RethrowFailure();
    CheckState(!stopping_, "MappingWorker::Queue: stopped");
    queue_.push_back({std::move(job), nullptr});
  }
  wake_.notify_one();
}

FrameResult MappingWorker::Run(MappingJob job) {
  auto done = std::make_shared<std::promise<FrameResult>>();
  std::future<FrameResult> result = done->get_future();
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    RethrowFailure();
    CheckState(!stopping_, "MappingWorker::Run: stopped");
    queue_.push_back({std::move(job), std::move(done)});
  }
  wake_.notify_one();
  return result.get();
}

void MappingWorker::WaitFor(std::int64_t frame_id) {
  std::unique_lock<std::mutex> lock(mutex_);
  idle_.wait(lock, [&] { return DoneOrEnded(frame_id); });
  RethrowFailure();
}

bool MappingWorker::WaitFor(std::int64_t frame_id, std::chrono::steady_clock::time_point deadline) {
  std::unique_lock<std::mutex> lock(mutex_);
  const bool done = idle_.wait_until(lock, deadline, [&] { return DoneOrEnded(frame_id); });
  RethrowFailure();
  return done && done_through_ >= frame_id;
}

void MappingWorker::Drain() {
  std::unique_lock<std::mutex> lock(mutex_);
  idle_.wait(lock, [this] { return (queue_.empty() && !busy_) || stopping_; });
  RethrowFailure();
}

void MappingWorker::Stop() {
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    if (stopping_ && !thread_.joinable()) return;
    stopping_ = true;
    queue_.clear();  // waiting refinements only: the caller is not waiting on any job now
  }
  wake_.notify_all();
  idle_.notify_all();
  if (thread_.joinable()) thread_.join();
}

std::int64_t MappingWorker::Skipped() const {
  const std::lock_guard<std::mutex> lock(mutex_);
  return skipped_;
}

void MappingWorker::Loop() {
  NameThisThread("px-mapping");
  for (;;) {
    Entry entry;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      wake_.wait(lock, [this] { return stopping_ || !queue_.empty(); });
      if (stopping_) return;
      entry = std::move(queue_.front());
      queue_.pop_front();
      entry.job.newer_waiting = !queue_.empty();
      busy_ = true;
    }
    idle_.notify_all();  // room in the queue: a caller waiting for room goes on now
    const bool waited = entry.done != nullptr;
    // Jobs the caller waits for or is idle during may have both cores; a keyframe request
    // shares them with live tracking (docs/realtime.md, "Thread budget").
    tbb::task_arena& arena = waited || entry.job.caller_idle ? waited_arena_
                             : entry.job.keep                ? keyframe_arena_
                                                             : arena_;
    std::exception_ptr error;
    std::optional<FrameResult> result;
    arena.execute([&] {
      try {
        result = process_(entry.job);
      } catch (...) {
        error = std::current_exception();
      }
    });
    if (entry.done) {
      error ? entry.done->set_exception(error) : entry.done->set_value(std::move(*result));
      entry.done.reset();
    }
    {
      const std::lock_guard<std::mutex> lock(mutex_);
      if (error && !waited) failure_ = error;
      done_through_ = std::max(done_through_, entry.job.FrameId());
      busy_ = false;
    }
    idle_.notify_all();
  }
}

}  // namespace parallax
