// The frames kept for refining a keyframe when it is left: bounded, evenly thinned, the
// newest always there, a new keyframe's frames never mixed with an older one's.

#include "backend/keyframe_window.hpp"

#include <gtest/gtest.h>

#include <memory>
#include <vector>

namespace parallax {
namespace {

std::shared_ptr<const Frame> TinyFrame(std::int64_t id) {
  return std::make_shared<const Frame>(id, 0.1 * static_cast<double>(id),
                                       PinholeCamera(16, 16, 10, 10, 7.5, 7.5),
                                       ImageU8(16, 16, static_cast<std::uint8_t>(id)));
}

/// Ids of the selected frames; each frame's pose carries its id as x translation too, so
/// a pose paired with the wrong frame shows.
std::vector<std::int64_t> SelectedIds(const KeyframeWindow& window, std::size_t count) {
  std::vector<std::int64_t> ids;
  for (const RefinementFrame& f : window.Select(count)) {
    EXPECT_DOUBLE_EQ(f.T_kf_frame.Translation().x(), static_cast<double>(f.frame->Id()));
    ids.push_back(f.frame->Id());
  }
  return ids;
}

SE3d PoseOf(std::int64_t id) {
  return SE3d(SO3d(), Eigen::Vector3d(static_cast<double>(id), 0.0, 0.0));
}

TEST(KeyframeWindow, SelectsFramesSpreadOverTheWindowWithTheNewest) {
  KeyframeWindow window(16);
  for (std::int64_t id = 0; id < 7; ++id) window.Add(3, TinyFrame(id), PoseOf(id));
  EXPECT_EQ(window.FramesSeen(), 7u);
  EXPECT_EQ(window.KeyframeId(), 3);
  EXPECT_EQ(SelectedIds(window, 4), (std::vector<std::int64_t>{0, 2, 4, 6}));
  EXPECT_EQ(SelectedIds(window, 2), (std::vector<std::int64_t>{0, 6}));
  EXPECT_EQ(SelectedIds(window, 10).size(), 7u);  // fewer held than asked: all of them
}

TEST(KeyframeWindow, ALongWindowIsThinnedEvenlyAndStaysBounded) {
  KeyframeWindow window(4);
  std::weak_ptr<const Frame> first_dropped;
  for (std::int64_t id = 0; id < 20; ++id) {
    auto frame = TinyFrame(id);
    if (id == 1) first_dropped = frame;
    window.Add(0, std::move(frame), PoseOf(id));
  }
  EXPECT_EQ(window.FramesSeen(), 20u);
  const std::vector<std::int64_t> held = SelectedIds(window, 100);
  ASSERT_LE(held.size(), 4u);
  EXPECT_EQ(held, (std::vector<std::int64_t>{0, 8, 16, 19}));  // every 8th and the newest
  EXPECT_EQ(held.front(), 0);                                  // the start of the window stays
  EXPECT_EQ(held.back(), 19);                                  // and so does the newest frame
  for (std::size_t k = 1; k < held.size(); ++k) EXPECT_LT(held[k - 1], held[k]);
  // A frame thinned out is released (the window bounds memory, not only a count).
  EXPECT_TRUE(first_dropped.expired());
}

TEST(KeyframeWindow, AnotherKeyframeStartsANewWindow) {
  KeyframeWindow window(8);
  for (std::int64_t id = 0; id < 5; ++id) window.Add(1, TinyFrame(id), PoseOf(id));
  window.Add(6, TinyFrame(6), PoseOf(6));
  EXPECT_EQ(window.KeyframeId(), 6);
  EXPECT_EQ(window.FramesSeen(), 1u);
  EXPECT_EQ(SelectedIds(window, 4), (std::vector<std::int64_t>{6}));
  window.Clear();
  EXPECT_EQ(window.KeyframeId(), -1);
  EXPECT_TRUE(window.Select(4).empty());
  EXPECT_THROW(KeyframeWindow(1), std::invalid_argument);
  EXPECT_THROW(window.Select(1), std::invalid_argument);
}

}  // namespace
}  // namespace parallax
