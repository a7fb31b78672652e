#include "backend/keyframe_window.hpp"

#include <algorithm>
#include <utility>

#include "core/check.hpp"

namespace parallax {

KeyframeWindow::KeyframeWindow(std::size_t capacity) : capacity_(capacity) {
  CheckArgument(capacity >= 2, "KeyframeWindow: capacity must be >= 2");
}

void KeyframeWindow::Add(std::int64_t keyframe_id, std::shared_ptr<const Frame> frame,
                         const SE3d& T_kf_frame) {
  if (keyframe_id != keyframe_id_) {
    Clear();
    keyframe_id_ = keyframe_id;
  }
  const std::size_t index = seen_++;
  newest_ = Entry{index, std::move(frame), T_kf_frame};
  if (index % stride_ != 0) return;
  if (held_.size() + 1 == capacity_) {
    // Full (one place stays for the newest): keep every second one, the stride doubles.
    std::vector<Entry> thinned;
    for (std::size_t i = 0; i < held_.size(); i += 2) thinned.push_back(std::move(held_[i]));
    held_ = std::move(thinned);
    stride_ *= 2;
    if (index % stride_ != 0) return;
  }
  held_.push_back(newest_);
}

void KeyframeWindow::Clear() {
  held_.clear();
  newest_ = Entry{};
  seen_ = 0;
  stride_ = 1;
  keyframe_id_ = -1;
}

std::vector<RefinementFrame> KeyframeWindow::Select(std::size_t count) const {
  CheckArgument(count >= 2, "KeyframeWindow::Select: count must be >= 2");
  std::vector<const Entry*> kept;
  for (const Entry& e : held_) kept.push_back(&e);
  if (newest_.frame && (kept.empty() || kept.back()->index != newest_.index)) {
    kept.push_back(&newest_);
  }
  std::vector<RefinementFrame> frames;
  for (const std::size_t i : SpreadIndices(kept.size(), count)) {
    frames.push_back({kept[i]->frame.get(), kept[i]->T_kf_frame});
  }
  return frames;
}

}  // namespace parallax
