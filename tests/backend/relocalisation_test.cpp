// Relocalisation ("kidnap"): after a stretch of black frames the camera reappears at a place
// mapped long before; it is found again within 3 frames, in the same world frame.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "backend/system.hpp"
#include "tests/tracking/render_fixture.hpp"
#include "tools/eval/alignment.hpp"
#include "tools/synth/motion.hpp"
#include "tools/synth/scene.hpp"

namespace parallax {
namespace {

struct Fed {
  std::int64_t frame_id = 0;
  SE3d T_w_c_true;
  bool after_gap = false;
};

/// Feeds rendered orbit views (or black frames) to a system and remembers the true poses.
class OrbitFeeder {
 public:
  explicit OrbitFeeder(const SystemOptions& options)
      : scene_(synth::MakeScene("room", 1)), system_(test::TestCamera(), options) {}

  /// From now on the camera is in another room of the same shape, furnished and decorated
  /// alike but with other textures (another seed).
  void MoveToSimilarRoom(std::uint64_t seed) { scene_ = synth::MakeScene("room", seed); }

  /// Orbit position k (150 per lap, 30 frames/s; k beyond 150 goes round again).
  FrameResult View(int k, bool after_gap) {
    const SE3d T_w_c = synth::CameraPose(synth::Motion::kOrbit, scene_.rig, k / 30.0, 5.0);
    return Feed(test::RenderTestImage(scene_, T_w_c), T_w_c, after_gap);
  }
  FrameResult Black() { return Feed(ImageU8(640, 480, 0), SE3d(), false); }
  System& Get() { return system_; }

  /// ATE RMSE (m) of the frames before and after the gap, after one Sim(3) alignment of
  /// every posed frame (the same world frame for both).
  std::pair<double, double> AteBeforeAndAfter(int* before_n, int* after_n) const {
    std::vector<Eigen::Vector3d> estimate, truth;
    std::vector<bool> after;
    for (const FramePose& p : system_.Trajectory()) {
      const Fed& f = fed_[static_cast<std::size_t>(p.frame_id)];
      estimate.push_back(p.T_w_c.Translation());
      truth.push_back(f.T_w_c_true.Translation());
      after.push_back(f.after_gap);
    }
    const Sim3d S = AlignUmeyama(estimate, truth, AlignmentMode::kSim3);
    double sq[2] = {0.0, 0.0};
    int n[2] = {0, 0};
    for (std::size_t i = 0; i < estimate.size(); ++i) {
      sq[after[i] ? 1 : 0] += (S * estimate[i] - truth[i]).squaredNorm();
      ++n[after[i] ? 1 : 0];
    }
    *before_n = n[0];
    *after_n = n[1];
    return {std::sqrt(sq[0] / std::max(1, n[0])), std::sqrt(sq[1] / std::max(1, n[1]))};
  }

 private:
  FrameResult Feed(const ImageU8& image, const SE3d& truth, bool after_gap) {
    FrameResult r = system_.ProcessFrame(image, static_cast<double>(fed_.size()) / 30.0);
    fed_.push_back({static_cast<std::int64_t>(fed_.size()), truth, after_gap});
    return r;
  }

  synth::Scene scene_;
  System system_;
  std::vector<Fed> fed_;
};

/// The frames after the gap are in the world frame of those before it: after one Sim(3)
/// alignment of all of them, their error is within twice the error before the gap.
void ExpectOneWorldFrame(const OrbitFeeder& feeder, int frames_before, int min_frames_after) {
  int before_n = 0, after_n = 0;
  const auto [before, after] = feeder.AteBeforeAndAfter(&before_n, &after_n);
  ::testing::Test::RecordProperty("ate_before_m", std::to_string(before));
  ::testing::Test::RecordProperty("ate_after_m", std::to_string(after));
  EXPECT_EQ(before_n, frames_before);
  EXPECT_GE(after_n, min_frames_after);
  EXPECT_LE(after, 2.0 * before + 1e-3);
}

bool Has(const FrameResult& r, SystemEvent::Kind kind) {
  return std::any_of(r.events.begin(), r.events.end(),
                     [&](const SystemEvent& e) { return e.kind == kind; });
}

TEST(Relocalisation, AKidnappedCameraIsFoundAgainInTheSameWorldFrame) {
  OrbitFeeder feeder{SystemOptions{}};
  // 100 frames round the orbit (240 degrees), 10 black frames, then the camera is back at
  // the stretch it saw 70-130 frames earlier (72 to 168 degrees round).
  for (int k = 0; k < 100; ++k) feeder.View(k, false);
  ASSERT_GT(feeder.Get().Graph().Size(), 5u);
  for (int k = 0; k < 10; ++k) EXPECT_FALSE(feeder.Black().T_w_c.has_value());
  int relocalised_at = -1;
  for (int k = 30; k < 70; ++k) {
    const FrameResult r = feeder.View(k, true);
    if (relocalised_at < 0 && Has(r, SystemEvent::Kind::kRelocalised)) relocalised_at = k - 30;
  }
  ASSERT_GE(relocalised_at, 0) << "never relocalised";
  RecordProperty("relocalised_on_usable_frame", relocalised_at + 1);
  EXPECT_LE(relocalised_at, 2) << "relocalised on the " << relocalised_at + 1 << "th usable frame";
  EXPECT_GE(feeder.Get().Backend().relocalisations, 1);
  EXPECT_EQ(feeder.Get().Backend().maps_started, 0);
  ExpectOneWorldFrame(feeder, 100, 37);
}

TEST(Relocalisation, ACameraThatReappearsSomewhereNewStartsANewMapMergedOnItsReturn) {
  SystemOptions options;
  options.new_map_after_lost_s = 0.5;
  OrbitFeeder feeder(options);
  // 60 frames (0 to 144 degrees), 20 black frames (0.67 s), then the camera reappears at
  // 240 degrees, a view the map never had, and goes on round past its start (432 degrees).
  for (int k = 0; k < 60; ++k) feeder.View(k, false);
  for (int k = 0; k < 20; ++k) feeder.Black();
  bool new_map = false;
  int merged_at = -1;
  for (int k = 100; k < 190; ++k) {
    const FrameResult r = feeder.View(k, true);
    new_map |= Has(r, SystemEvent::Kind::kNewMap);
    if (merged_at < 0 && Has(r, SystemEvent::Kind::kMapsMerged)) merged_at = k;
  }
  EXPECT_TRUE(new_map);
  EXPECT_EQ(feeder.Get().Backend().maps_started, 1);
  ASSERT_GE(merged_at, 0) << "the maps were never merged";
  RecordProperty("merged_at_orbit_position", merged_at);
  EXPECT_EQ(feeder.Get().Graph().NumMaps(), 1);
  ExpectOneWorldFrame(feeder, 60, 60);
}

TEST(Relocalisation, ASimilarRoomIsNeitherRelocalisedInNorMergedWithTheFirst) {
  SystemOptions options;
  options.new_map_after_lost_s = 0.5;
  OrbitFeeder feeder(options);
  // 100 frames round the first room; 20 black frames; then the camera is in a second room of
  // the same shape and furniture (other textures), at the views the first room's map has.
  for (int k = 0; k < 100; ++k) feeder.View(k, false);
  for (int k = 0; k < 20; ++k) feeder.Black();
  feeder.MoveToSimilarRoom(2);
  for (int k = 0; k < 100; ++k) feeder.View(k, true);
  const BackendStats& stats = feeder.Get().Backend();
  RecordProperty("relocalisation_attempts", stats.relocalisation_attempts);
  RecordProperty("loop_checks", stats.loop_checks);
  EXPECT_GT(stats.relocalisation_attempts, 0);  // it was lost and tried
  EXPECT_EQ(stats.relocalisations, 0);
  EXPECT_EQ(stats.maps_started, 1);
  EXPECT_EQ(stats.merges, 0);
  EXPECT_EQ(feeder.Get().Graph().NumMaps(), 2);
}

}  // namespace
}  // namespace parallax
