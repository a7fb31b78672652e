#include "tools/dataset/frame_prefetcher.hpp"

#include "core/check.hpp"

namespace parallax {

FramePrefetcher::FramePrefetcher(DatasetReader* reader, const Undistorter* undistorter,
                                 std::size_t capacity)
    : reader_(reader), undistorter_(undistorter), capacity_(capacity) {
  CheckArgument(reader_ != nullptr && undistorter_ != nullptr,
                "FramePrefetcher: reader and undistorter are required");
  CheckArgument(capacity_ >= 1, "FramePrefetcher: capacity must be >= 1");
  thread_ = std::thread([this] { ReadAhead(); });
}

FramePrefetcher::~FramePrefetcher() {
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
  }
  space_.notify_all();
  thread_.join();
}

void FramePrefetcher::ReadAhead() {
  for (;;) {
    {
      std::unique_lock<std::mutex> lock(mutex_);
      space_.wait(lock, [this] { return stopping_ || queue_.size() < capacity_; });
      if (stopping_) return;
    }
    std::optional<PreparedFrame> prepared;
    std::exception_ptr error;
    try {
      if (std::optional<DatasetFrame> frame = reader_->Next()) {
        prepared.emplace();
        prepared->index = frame->index;
        prepared->timestamp = frame->timestamp;
        undistorter_->Apply(frame->image, &prepared->image);
      }
    } catch (...) {
      error = std::current_exception();
    }
    {
      const std::lock_guard<std::mutex> lock(mutex_);
      if (prepared) {
        queue_.push_back(std::move(*prepared));
      } else {
        done_ = true;
        error_ = error;
      }
    }
    ready_.notify_one();
    if (!prepared) return;
  }
}

std::optional<PreparedFrame> FramePrefetcher::Next() {
  std::unique_lock<std::mutex> lock(mutex_);
  ready_.wait(lock, [this] { return !queue_.empty() || done_; });
  if (queue_.empty()) {
    if (error_) std::rethrow_exception(error_);
    return std::nullopt;
  }
  PreparedFrame frame = std::move(queue_.front());
  queue_.pop_front();
  lock.unlock();
  space_.notify_one();
  return frame;
}

}  // namespace parallax
