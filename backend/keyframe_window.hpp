#pragma once
// The frames that updated the current keyframe's depth, kept for the joint refinement of the
// keyframe when it is left (docs/math/keyframe_refinement.md, "Every keyframe").

#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include "backend/keyframe_refinement.hpp"
#include "core/frame.hpp"
#include "core/se3.hpp"

namespace parallax {

/// A bounded, evenly thinned record of the frames of one keyframe's window. Holding every
/// frame's pyramid (about 6 MB at 640x480) for a long window would cost more memory than the
/// map itself: the window keeps every `stride`-th frame (0, s, 2s, ...) and the newest one,
/// at most `capacity` in all; when the kept ones fill it, the stride doubles and every second
/// one is released, so they stay evenly spread over the whole window.
class KeyframeWindow {
 public:
  /// `capacity` >= 2.
  explicit KeyframeWindow(std::size_t capacity);

  /// Adds a frame of keyframe `keyframe_id` with its pose T_kf_frame (keyframe units); a
  /// frame of another keyframe than the held ones' starts a new window.
  void Add(std::int64_t keyframe_id, std::shared_ptr<const Frame> frame, const SE3d& T_kf_frame);
  /// Forgets every frame.
  void Clear();
  /// The keyframe the window belongs to (-1 when empty).
  std::int64_t KeyframeId() const { return keyframe_id_; }
  /// Frames added since the window started (held or thinned out).
  std::size_t FramesSeen() const { return seen_; }
  /// At most `count` (>= 2) held frames, spread over the window, oldest first, the newest
  /// always included.
  std::vector<RefinementFrame> Select(std::size_t count) const;

 private:
  struct Entry {
    std::size_t index = 0;  ///< position in the window (frames added before it)
    std::shared_ptr<const Frame> frame;
    SE3d T_kf_frame;
  };
  std::size_t capacity_;
  std::int64_t keyframe_id_ = -1;
  std::size_t seen_ = 0;
  std::size_t stride_ = 1;
  std::vector<Entry> held_;  ///< frames at multiples of stride_, at most capacity_ - 1
  Entry newest_;             ///< the newest frame (also in held_ when on the stride)
};

}  // namespace parallax
