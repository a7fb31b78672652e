// The C API's thread-safety promise ("every function may be called from any thread", calls
// on one system serialised) under the real-time mode, in the `threads` label so that CI runs
// it under ThreadSanitizer: one thread feeds frames while another queries the map, polls
// events and asks mapping to finish; a reset and a destruction with start frames queued.

#include <gtest/gtest.h>

#include <atomic>
#include <thread>
#include <vector>

#include "parallax/parallax.h"
#include "tests/tracking/render_fixture.hpp"
#include "tools/synth/motion.hpp"
#include "tools/synth/scene.hpp"

namespace parallax {
namespace {

std::vector<ImageU8> OrbitImages(int count) {
  static const synth::Scene scene = synth::MakeScene("room", 1);
  std::vector<ImageU8> images;
  images.reserve(static_cast<std::size_t>(count));
  for (int k = 0; k < count; ++k) {
    images.push_back(test::RenderTestImage(
        scene, synth::CameraPose(synth::Motion::kOrbit, scene.rig, k / 30.0, 5.0)));
  }
  return images;
}

px_system* CreateRealtime() {
  const PinholeCamera K = test::TestCamera();
  const px_pinhole camera{K.Width(), K.Height(), K.Fx(), K.Fy(), K.Cx(), K.Cy()};
  px_system* system = nullptr;
  EXPECT_EQ(px_system_create(&camera, nullptr, 1, &system), PX_OK) << px_last_error();
  return system;
}

px_status Feed(px_system* system, const ImageU8& image, int k) {
  px_frame_result result;
  return px_system_process_frame(system, image.Data(), image.Width(), image.Height(), image.Width(),
                                 k / 30.0, &result);
}

TEST(CApiThreads, QueriesAndFinishMappingFromAnotherThreadWhileFeeding) {
  const std::vector<ImageU8> images = OrbitImages(45);
  px_system* system = CreateRealtime();
  ASSERT_NE(system, nullptr);
  std::atomic<bool> fed{false};
  std::atomic<int> failed_queries{0};
  std::thread queries([&] {
    while (!fed) {
      size_t count = 0;
      double T_w_c[16];
      int has_pose = 0, available = 0;
      px_event event;
      const px_status statuses[] = {px_system_keyframes(system, nullptr, 0, &count),
                                    px_system_map_points(system, nullptr, 0, &count),
                                    px_system_frame_pose(system, 5, T_w_c, &has_pose),
                                    px_system_poll_event(system, &event, &available, nullptr),
                                    px_system_finish_mapping(system)};
      for (const px_status s : statuses) failed_queries += s == PX_OK ? 0 : 1;
    }
  });
  int failed_frames = 0;
  for (int k = 0; k < static_cast<int>(images.size()); ++k) {
    failed_frames += Feed(system, images[static_cast<std::size_t>(k)], k) == PX_OK ? 0 : 1;
  }
  fed = true;
  queries.join();
  EXPECT_EQ(failed_frames, 0);
  EXPECT_EQ(failed_queries.load(), 0);
  ASSERT_EQ(px_system_finish_mapping(system), PX_OK);
  int posed = 0;
  for (int k = 0; k < static_cast<int>(images.size()); ++k) {
    double T_w_c[16];
    int has_pose = 0;
    ASSERT_EQ(px_system_frame_pose(system, k, T_w_c, &has_pose), PX_OK);
    posed += has_pose;
  }
  EXPECT_GE(posed, 40);
  // A reset with start frames queued, then a destruction with start frames queued.
  for (int k = 0; k < 6; ++k) Feed(system, images[static_cast<std::size_t>(k)], k);
  ASSERT_EQ(px_system_reset(system), PX_OK);
  for (int k = 0; k < 6; ++k) {
    EXPECT_EQ(Feed(system, images[static_cast<std::size_t>(k)], k), PX_OK) << px_last_error();
  }
  px_system_destroy(system);
}

}  // namespace
}  // namespace parallax
