#pragma once
// Reads and undistorts the next frames on a second thread while the current one is processed.

#include <condition_variable>
#include <cstddef>
#include <deque>
#include <exception>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "core/undistorter.hpp"
#include "tools/dataset/dataset_reader.hpp"
#include "tools/dataset/photometric_corrector.hpp"

namespace parallax {

/// A frame ready for System::ProcessFrame: undistorted to the engine's pinhole camera.
struct PreparedFrame {
  std::size_t index = 0;
  double timestamp = 0.0;  ///< NaN for an unreadable frame whose time the reader cannot tell
  ImageU8 image;
  /// Non-empty for a frame that could not be read (skip_unreadable): the reader's message
  /// naming the file; `image` is then empty.
  std::string error;
};

/// Decoding a PNG and undistorting it take 2-3 ms of a 640x480 frame's budget on a single
/// thread; a reader thread does it up to `capacity` frames ahead (a bounded queue with
/// condition variables, no polling). Frames come out in order and are the same whether or not
/// they were read ahead, so deterministic runs stay bit-identical. A reader error (unreadable
/// image) is rethrown by Next() after the frames before it, as a direct read would.
class FramePrefetcher {
 public:
  /// `reader` and `undistorter` must outlive this object and are used by its thread only.
  /// With `skip_unreadable`, an unreadable or corrupt image (InputError from the reader) comes
  /// out as a frame with `error` set and reading goes on; otherwise Next() rethrows it.
  /// `photometric` (may be null; must outlive this object) undoes the response and vignette
  /// before undistortion.
  FramePrefetcher(DatasetReader* reader, const Undistorter* undistorter, std::size_t capacity = 4,
                  bool skip_unreadable = false, const PhotometricCorrector* photometric = nullptr);
  ~FramePrefetcher();
  FramePrefetcher(const FramePrefetcher&) = delete;
  FramePrefetcher& operator=(const FramePrefetcher&) = delete;

  /// The next frame, nullopt at the end of the sequence. Rethrows the reader's exception.
  std::optional<PreparedFrame> Next();

 private:
  void ReadAhead();

  DatasetReader* reader_;
  const Undistorter* undistorter_;
  const PhotometricCorrector* photometric_;
  std::size_t capacity_;
  bool skip_unreadable_;
  std::vector<double> timestamps_;  ///< of every frame, when the reader knows them
  std::size_t next_index_ = 0;
  std::mutex mutex_;
  std::condition_variable space_, ready_;
  std::deque<PreparedFrame> queue_;
  bool done_ = false;      // the reader reached the end or failed
  bool stopping_ = false;  // the consumer is going away
  std::exception_ptr error_;
  std::thread thread_;  // last: started once everything above is initialised
};

}  // namespace parallax
