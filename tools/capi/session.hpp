#pragma once
// The C++ side of one px_system (docs/c_api.md): validation of the C arguments, the
// rectification of input frames, the event queue, and the "failed" state after an internal
// error. Not thread-safe by itself: the C layer serialises calls with the handle's mutex.

#include <cstdint>
#include <deque>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "backend/system.hpp"
#include "core/camera.hpp"
#include "core/undistorter.hpp"
#include "parallax/parallax.h"

namespace parallax::capi {

/// A failure with the status the C caller gets.
class StatusError : public std::runtime_error {
 public:
  StatusError(px_status status, const std::string& message)
      : std::runtime_error(message), status_(status) {}
  px_status Status() const { return status_; }

 private:
  px_status status_;
};

struct SessionOptions {
  /// Undistorted frames are pinhole images of Undistorter(camera, rectification).
  UndistorterOptions rectification;
  SystemOptions system;
  /// Pending events kept for px_system_poll_event; older ones are dropped first.
  std::size_t max_events = 4096;
};

class Session {
 public:
  /// Throws StatusError (invalid argument) naming the bad value.
  Session(const Camera& camera, const SessionOptions& options);

  /// Validates everything before anything changes (StatusError); an exception from the
  /// engine marks the session failed (every later frame: invalid state until Reset).
  px_frame_result ProcessFrame(const std::uint8_t* gray, int width, int height, int stride_bytes,
                               double timestamp_s);
  /// Points as x y z floats.
  std::vector<float> MapPoints() const;
  std::vector<px_keyframe> Keyframes() const;
  std::optional<SE3d> FramePose(std::int64_t frame_id) const;
  /// Oldest pending event, and how many were dropped since the last call.
  std::optional<px_event> PollEvent(std::uint64_t* dropped);

  /// System::FinishMapping: everything given so far mapped; its events queued. An engine
  /// exception marks the session failed, as in ProcessFrame.
  void FinishMapping();
  void SaveMap(const std::string& path) const;
  /// A new system with the map; swapped in only when the load succeeded.
  void LoadMap(const std::string& path);
  void Reset();
  const PinholeCamera& EngineCamera() const { return undistorter_.OutputCamera(); }

 private:
  void RequireUsable() const;
  void QueueEvents(const FrameResult& result);
  px_tracking_state StateOf(const FrameResult& result) const;

  SessionOptions options_;
  Undistorter undistorter_;
  std::unique_ptr<System> system_;
  std::optional<double> last_timestamp_;
  /// Set when the engine threw during a frame: its state may be inconsistent.
  std::string failure_;
  std::deque<px_event> events_;
  std::uint64_t events_dropped_ = 0;
  ImageU8 input_;      ///< the caller's frame without row padding
  ImageU8 rectified_;  ///< ... rectified
};

/// Row-major 4x4 of a rigid transform.
void ToRowMajor(const SE3d& T, double out[16]);

}  // namespace parallax::capi
