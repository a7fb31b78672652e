// Relocalisation ("kidnap"): after a stretch of black frames the camera reappears at a place
// mapped long before; it is found again within 3 frames, in the same world frame.

#include <gtest/gtest.h>

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

TEST(Relocalisation, AKidnappedCameraIsFoundAgainInTheSameWorldFrame) {
  const synth::Scene scene = synth::MakeScene("room", 1);
  const auto pose = [&](int k) {
    return synth::CameraPose(synth::Motion::kOrbit, scene.rig, k / 30.0, 150 / 30.0);
  };
  System system(test::TestCamera());
  std::vector<Fed> fed;
  int index = 0;
  const auto feed = [&](const ImageU8& image, const SE3d& truth, bool after_gap) {
    const FrameResult r = system.ProcessFrame(image, index++ / 30.0);
    fed.push_back({index - 1, truth, after_gap});
    return r;
  };
  // 100 frames round the orbit (240 degrees), 10 black frames, then the camera is back at
  // the stretch it saw 70-130 frames earlier (72 to 168 degrees round).
  for (int k = 0; k < 100; ++k) feed(test::RenderTestImage(scene, pose(k)), pose(k), false);
  ASSERT_GT(system.Graph().Size(), 5u);
  const ImageU8 black(640, 480, 0);
  for (int k = 0; k < 10; ++k) EXPECT_FALSE(feed(black, SE3d(), false).T_w_c.has_value());
  int relocalised_at = -1;
  for (int k = 30; k < 70; ++k) {
    const FrameResult r = feed(test::RenderTestImage(scene, pose(k)), pose(k), true);
    for (const SystemEvent& e : r.events) {
      if (e.kind == SystemEvent::Kind::kRelocalised && relocalised_at < 0) relocalised_at = k - 30;
    }
  }
  ASSERT_GE(relocalised_at, 0) << "never relocalised";
  RecordProperty("relocalised_on_usable_frame", relocalised_at + 1);
  EXPECT_LE(relocalised_at, 2) << "relocalised on the " << relocalised_at + 1 << "th usable frame";
  EXPECT_GE(system.Backend().relocalisations, 1);
  // One Sim(3) alignment of every posed frame: the frames after the gap must sit in the same
  // world frame as those before it.
  std::vector<Eigen::Vector3d> estimate, truth;
  std::vector<bool> after;
  for (const FramePose& p : system.Trajectory()) {
    const Fed& f = fed[static_cast<std::size_t>(p.frame_id)];
    estimate.push_back(p.T_w_c.Translation());
    truth.push_back(f.T_w_c_true.Translation());
    after.push_back(f.after_gap);
  }
  const Sim3d S = AlignUmeyama(estimate, truth, AlignmentMode::kSim3);
  double before_sq = 0.0, after_sq = 0.0;
  int before_n = 0, after_n = 0;
  for (std::size_t i = 0; i < estimate.size(); ++i) {
    const double e = (S * estimate[i] - truth[i]).squaredNorm();
    (after[i] ? after_sq : before_sq) += e;
    ++(after[i] ? after_n : before_n);
  }
  const double before_rmse = std::sqrt(before_sq / before_n);
  const double after_rmse = std::sqrt(after_sq / after_n);
  RecordProperty("ate_before_m", std::to_string(before_rmse));
  RecordProperty("ate_after_m", std::to_string(after_rmse));
  EXPECT_EQ(before_n, 100);
  EXPECT_GE(after_n, 37);
  EXPECT_LE(after_rmse, 2.0 * before_rmse + 1e-3);
}

}  // namespace
}  // namespace parallax
