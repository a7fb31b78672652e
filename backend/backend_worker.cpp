#include "backend/backend_worker.hpp"

#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <utility>

#include "backend/arena_width.hpp"
#include "core/check.hpp"
#include "core/thread_name.hpp"

namespace parallax {

BackendWorker::BackendWorker(std::function<void()> run, int threads, int drain_threads, int nice)
    : run_(std::move(run)), arena_(ArenaWidth(threads)), drain_arena_(ArenaWidth(drain_threads)) {
  CheckArgument(static_cast<bool>(run_), "BackendWorker: no work function");
  thread_ = std::thread([this, nice] { Loop(nice); });
}

BackendWorker::~BackendWorker() { Stop(); }

void BackendWorker::RethrowFailure() {
  if (failure_) std::rethrow_exception(std::exchange(failure_, nullptr));
}

void BackendWorker::Notify() {
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    RethrowFailure();
    CheckState(!stopping_, "BackendWorker::Notify: stopped");
    requested_ = true;
  }
  wake_.notify_one();
}

void BackendWorker::Drain() {
  ++drainers_;
  std::unique_lock<std::mutex> lock(mutex_);
  idle_.wait(lock, [this] { return (!requested_ && !busy_) || stopping_; });
  --drainers_;
  RethrowFailure();
}

bool BackendWorker::Draining() const { return drainers_.load() > 0; }

void BackendWorker::RunStep(const std::function<void()>& step) {
  // The work that remains when the caller drains (the end of a sequence) has the cores to
  // itself: tracking and mapping are done.
  if (Draining()) {
    drain_arena_.execute(step);
  } else {
    step();
  }
}

bool BackendWorker::Stop() {
  bool waiting = false;
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    if (stopping_ && !thread_.joinable()) return false;
    stopping_ = true;
    waiting = std::exchange(requested_, false);
  }
  wake_.notify_all();
  idle_.notify_all();
  if (thread_.joinable()) thread_.join();
  return waiting;
}

std::int64_t BackendWorker::Runs() const {
  const std::lock_guard<std::mutex> lock(mutex_);
  return runs_;
}

void BackendWorker::Loop(int nice) {
  NameThisThread("px-backend");
  if (nice != 0) {
    // Per-thread on Linux (the thread id as process id); failing leaves the default, which
    // only costs latency.
    setpriority(PRIO_PROCESS, static_cast<id_t>(syscall(SYS_gettid)), nice);
  }
  for (;;) {
    {
      std::unique_lock<std::mutex> lock(mutex_);
      wake_.wait(lock, [this] { return stopping_ || requested_; });
      if (stopping_) return;
      requested_ = false;
      busy_ = true;
      ++runs_;
    }
    std::exception_ptr error;
    arena_.execute([&] {
      try {
        run_();
      } catch (...) {
        error = std::current_exception();
      }
    });
    {
      const std::lock_guard<std::mutex> lock(mutex_);
      if (error) failure_ = error;
      busy_ = false;
    }
    idle_.notify_all();
  }
}

}  // namespace parallax
