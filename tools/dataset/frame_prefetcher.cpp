#include "tools/dataset/frame_prefetcher.hpp"

#include <limits>

#include "core/check.hpp"
#include "core/thread_name.hpp"
#include "tools/dataset/input_error.hpp"

namespace parallax {

FramePrefetcher::FramePrefetcher(DatasetReader* reader, const Undistorter* undistorter,
                                 std::size_t capacity, bool skip_unreadable,
                                 const PhotometricCorrector* photometric)
    : reader_(reader),
      undistorter_(undistorter),
      photometric_(photometric),
      capacity_(capacity),
      skip_unreadable_(skip_unreadable) {
  CheckArgument(reader_ != nullptr && undistorter_ != nullptr,
                "FramePrefetcher: reader and undistorter are required");
  timestamps_ = reader_->FrameTimestamps();
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
  NameThisThread("px-reader");
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
        if (photometric_ != nullptr) photometric_->Apply(frame->image, &frame->image);
        undistorter_->Apply(frame->image, &prepared->image);
      }
    } catch (const InputError& e) {
      // The file-list readers move past a frame before reading it, so the next call reads
      // the frame after the broken one.
      if (skip_unreadable_ && next_index_ < reader_->NumFrames()) {
        prepared.emplace();
        prepared->index = next_index_;
        prepared->timestamp = next_index_ < timestamps_.size()
                                  ? timestamps_[next_index_]
                                  : std::numeric_limits<double>::quiet_NaN();
        prepared->error = e.what();
      } else {
        error = std::current_exception();
      }
    } catch (...) {
      error = std::current_exception();
    }
    if (prepared) next_index_ = prepared->index + 1;
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
