#pragma once
// Plays a dataset back like a live camera (`parallax run --realtime --rate R`): each frame
// becomes available at its timestamp / R after the first; a frame that arrives while the
// previous one has not been taken replaces it, and the replaced one is dropped, as a camera
// driver with a one-frame buffer does (docs/realtime.md).

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <exception>
#include <mutex>
#include <optional>
#include <thread>
#include <utility>
#include <vector>

#include "tools/dataset/frame_prefetcher.hpp"

namespace parallax {

class CameraPlayback {
 public:
  /// `frames` must outlive the playback; `rate` > 0 (1: real time). Frames before index
  /// `first` are passed over at once (a run that starts later in the sequence).
  CameraPlayback(FramePrefetcher* frames, double rate, std::size_t first = 0);
  /// Stops the playback thread at once (it waits on a condition variable, never sleeps).
  ~CameraPlayback();
  CameraPlayback(const CameraPlayback&) = delete;
  CameraPlayback& operator=(const CameraPlayback&) = delete;

  /// The newest frame not yet taken (waits for one); nullopt at the end. Rethrows a reader
  /// error.
  std::optional<PreparedFrame> Next();
  /// Index and timestamp of the frames dropped since the last call.
  std::vector<std::pair<std::size_t, double>> TakeDropped();

 private:
  void Play();

  FramePrefetcher* frames_;
  double rate_;
  std::size_t first_;
  mutable std::mutex mutex_;
  std::condition_variable changed_;
  std::optional<PreparedFrame> slot_;
  bool finished_ = false;
  bool stopping_ = false;
  std::exception_ptr error_;
  std::vector<std::pair<std::size_t, double>> dropped_;
  std::thread thread_;  ///< last: starts when the rest exists
};

}  // namespace parallax
