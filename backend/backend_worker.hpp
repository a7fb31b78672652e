#pragma once
// The backend thread of the real-time mode (docs/realtime.md): constraint search, pose-graph
// optimisation and loop closure for finished keyframes, behind the mapping thread. The work
// itself lives in System (a batch of every keyframe waiting); this class owns the thread,
// wakes it with a condition variable and hands its exceptions to the caller.

#include <tbb/task_arena.h>

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>

namespace parallax {

class BackendWorker {
 public:
  /// `run` does the waiting work (all of it: requests made while it runs wake it again);
  /// `threads`: TBB concurrency of its arena; `drain_threads`: that of the arena its steps
  /// (RunStep) move to while a caller waits in Drain() (the caller is idle then; under
  /// ThreadSanitizer 1, see ArenaWidth); `nice`: the thread's scheduling niceness (Linux; 0
  /// leaves it as the caller's, a positive value lets tracking and mapping go first on a busy
  /// machine). The thread starts here.
  BackendWorker(std::function<void()> run, int threads, int drain_threads, int nice);
  /// Stop().
  ~BackendWorker();
  BackendWorker(const BackendWorker&) = delete;
  BackendWorker& operator=(const BackendWorker&) = delete;

  /// There is work: `run` is called (again) soon. Rethrows (once) an exception `run` threw.
  void Notify();
  /// Returns once no work is waiting or running (rethrows as Notify does).
  void Drain();
  /// Lets a running `run` finish, drops the request for more and joins the thread.
  /// Idempotent. Returns true when work was waiting (the caller settles it another way).
  bool Stop();
  /// Times `run` was called.
  std::int64_t Runs() const;
  /// Whether a caller waits in Drain().
  bool Draining() const;
  /// For `run`, on the worker's thread: runs `step` (one keyframe's work), in the drain
  /// arena when a caller waits in Drain(), else in the worker's own.
  void RunStep(const std::function<void()>& step);

 private:
  void Loop(int nice);
  void RethrowFailure();  // precondition: mutex_ held

  std::function<void()> run_;
  tbb::task_arena arena_;
  tbb::task_arena drain_arena_;
  std::atomic<int> drainers_{0};  ///< callers waiting in Drain()
  mutable std::mutex mutex_;
  std::condition_variable wake_;  ///< work was requested, or stop
  std::condition_variable idle_;  ///< a run finished
  bool requested_ = false;
  bool busy_ = false;
  bool stopping_ = false;
  std::exception_ptr failure_;
  std::int64_t runs_ = 0;
  std::thread thread_;  ///< last: started when everything above exists
};

}  // namespace parallax
