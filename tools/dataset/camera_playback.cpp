#include "tools/dataset/camera_playback.hpp"

#include <cmath>

#include "core/check.hpp"
#include "core/thread_name.hpp"

namespace parallax {

CameraPlayback::CameraPlayback(FramePrefetcher* frames, double rate, std::size_t first)
    : frames_(frames), rate_(rate), first_(first) {
  CheckArgument(frames_ != nullptr, "CameraPlayback: no frames");
  CheckArgument(rate_ > 0.0 && std::isfinite(rate_), "CameraPlayback: rate must be > 0");
  thread_ = std::thread([this] { Play(); });
}

CameraPlayback::~CameraPlayback() {
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
  }
  changed_.notify_all();
  thread_.join();
}

void CameraPlayback::Play() {
  NameThisThread("px-camera");
  using Clock = std::chrono::steady_clock;
  std::optional<double> first_timestamp;
  Clock::time_point start;
  try {
    for (;;) {
      std::optional<PreparedFrame> frame = frames_->Next();
      if (!frame) break;
      if (frame->index < first_) continue;
      std::unique_lock<std::mutex> lock(mutex_);
      if (std::isfinite(frame->timestamp)) {
        if (!first_timestamp) {
          first_timestamp = frame->timestamp;
          start = Clock::now();
        }
        const auto due =
            start + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(
                        (frame->timestamp - *first_timestamp) / rate_));
        // The camera's clock: wait for the frame's time unless stopped.
        changed_.wait_until(lock, due, [this] { return stopping_; });
      }
      if (stopping_) return;
      if (slot_) dropped_.emplace_back(slot_->index, slot_->timestamp);
      slot_ = std::move(frame);
      lock.unlock();
      changed_.notify_all();
    }
  } catch (...) {
    const std::lock_guard<std::mutex> lock(mutex_);
    error_ = std::current_exception();
  }
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    finished_ = true;
  }
  changed_.notify_all();
}

std::optional<PreparedFrame> CameraPlayback::Next() {
  std::unique_lock<std::mutex> lock(mutex_);
  changed_.wait(lock, [this] { return slot_.has_value() || finished_; });
  if (slot_) {
    std::optional<PreparedFrame> frame = std::move(slot_);
    slot_.reset();
    return frame;
  }
  if (error_) std::rethrow_exception(error_);
  return std::nullopt;
}

std::vector<std::pair<std::size_t, double>> CameraPlayback::TakeDropped() {
  const std::lock_guard<std::mutex> lock(mutex_);
  return std::exchange(dropped_, {});
}

}  // namespace parallax
