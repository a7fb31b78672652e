// FramePrefetcher: frames in order and unchanged, reader errors rethrown in place, early stop.

#include "tools/dataset/frame_prefetcher.hpp"

#include <gtest/gtest.h>

#include <stdexcept>

#include "tools/dataset/input_error.hpp"

namespace parallax {
namespace {

// A sequence of `count` 16x12 images whose pixels all equal the frame index; frame
// `fail_at` (if >= 0) throws InputError like an unreadable PNG.
class FakeReader : public DatasetReader {
 public:
  FakeReader(int count, int fail_at) : count_(count), fail_at_(fail_at) {}
  DatasetFormat Format() const override { return DatasetFormat::kImages; }
  const Camera& GetCamera() const override { return camera_; }
  std::size_t NumFrames() const override { return static_cast<std::size_t>(count_); }
  std::optional<DatasetFrame> Next() override {
    if (next_ == count_) return std::nullopt;
    if (next_ == fail_at_) throw InputError("frame_" + std::to_string(next_) + ".png", "corrupt");
    DatasetFrame frame;
    frame.index = static_cast<std::size_t>(next_);
    frame.timestamp = 0.5 * next_;
    frame.image = ImageU8(16, 12, static_cast<std::uint8_t>(next_));
    ++next_;
    return frame;
  }

 private:
  Camera camera_{CameraModel::kPinhole, 16, 12, 20, 20, 7.5, 5.5};
  int count_, fail_at_, next_ = 0;
};

TEST(FramePrefetcher, DeliversEveryFrameInOrderUnchanged) {
  FakeReader reader(50, -1);
  const Undistorter undistorter(reader.GetCamera(), {});
  FramePrefetcher frames(&reader, &undistorter, 3);
  for (int i = 0; i < 50; ++i) {
    const auto frame = frames.Next();
    ASSERT_TRUE(frame.has_value()) << i;
    EXPECT_EQ(frame->index, static_cast<std::size_t>(i));
    EXPECT_EQ(frame->timestamp, 0.5 * i);
    EXPECT_EQ(frame->image(7, 5), i);
  }
  EXPECT_FALSE(frames.Next().has_value());
  EXPECT_FALSE(frames.Next().has_value());  // stays at the end
}

TEST(FramePrefetcher, RethrowsTheReadersErrorAfterTheFramesBeforeIt) {
  FakeReader reader(10, 4);
  const Undistorter undistorter(reader.GetCamera(), {});
  FramePrefetcher frames(&reader, &undistorter);
  for (int i = 0; i < 4; ++i) ASSERT_TRUE(frames.Next().has_value());
  try {
    frames.Next();
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("frame_4.png"), std::string::npos) << e.what();
  }
}

TEST(FramePrefetcher, StopsCleanlyBeforeTheEnd) {
  FakeReader reader(1000, -1);
  const Undistorter undistorter(reader.GetCamera(), {});
  {
    FramePrefetcher frames(&reader, &undistorter, 2);
    ASSERT_TRUE(frames.Next().has_value());
  }  // the reader thread is blocked on a full queue: destruction must wake and join it
  SUCCEED();
}

}  // namespace
}  // namespace parallax
