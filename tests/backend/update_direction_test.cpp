// UpdateDirection: blending the tracked translation direction with the essential matrix's, on
// rendered pairs with known motion.

#include "backend/update_direction.hpp"

#include <gtest/gtest.h>

#include <optional>

#include "core/angles.hpp"
#include "tests/backend/room_pair_fixture.hpp"

namespace parallax {
namespace {

TEST(BlendDirections, HalfwayWithTheTrackedLength) {
  const Eigen::Vector3d tracked(0.0, 0.0, 2.0), essential(0.1, 0.0, 1.0);  // 5.7 deg apart
  const Eigen::Vector3d b = BlendDirections(tracked, essential, 0.5, 10.0);
  EXPECT_NEAR(b.norm(), 2.0, 1e-12);
  EXPECT_NEAR(AngleBetweenDeg(b, tracked), AngleBetweenDeg(b, essential), 1e-9);
  EXPECT_NEAR(AngleBetweenDeg(b, tracked), 0.5 * AngleBetweenDeg(tracked, essential), 1e-9);
  EXPECT_EQ(BlendDirections(tracked, essential, 0.0, 10.0), tracked);
  EXPECT_NEAR(AngleBetweenDeg(BlendDirections(tracked, essential, 1.0, 10.0), essential), 0.0,
              1e-6);
}

TEST(BlendDirections, KeepsTrackingWhenTheyDisagreeOrOneIsZero) {
  const Eigen::Vector3d tracked(0.0, 0.0, 1.0), essential(1.0, 0.0, 1.0);  // 45 deg apart
  EXPECT_EQ(BlendDirections(tracked, essential, 0.5, 10.0), tracked);
  EXPECT_EQ(BlendDirections(tracked, Eigen::Vector3d::Zero(), 0.5, 10.0), tracked);
  EXPECT_EQ(BlendDirections(Eigen::Vector3d::Zero(), essential, 0.5, 10.0),
            Eigen::Vector3d::Zero());
}

TEST(UpdateDirectionOptions, RejectBadValues) {
  UpdateDirectionOptions o;
  o.essential_weight = 1.5;
  EXPECT_THROW(o.Check(), std::invalid_argument);
  o = {};
  o.max_angle_deg = 0.0;
  EXPECT_THROW(o.Check(), std::invalid_argument);
  o = {};
  o.min_relative_baseline = -1.0;
  EXPECT_THROW(o.Check(), std::invalid_argument);
}

class UpdateDirectionTest : public test::RoomPairTest {
 protected:
  ImageU8 Render(const SE3d& T_kf_c) const { return RenderImage(Moved(T_kf_c), 1.0f, 1.0); }
  /// The essential matrix's translation direction keyframe -> frame (the frame centre in
  /// keyframe coordinates), found with the check's own matcher; nullopt without a pair.
  std::optional<Eigen::Vector3d> EssentialDirection(const ImageU8& keyframe,
                                                    const ImageU8& frame) const {
    const std::optional<SE3d> T_kf_frame = EssentialPose(keyframe, frame);
    if (!T_kf_frame) return std::nullopt;
    return T_kf_frame->Translation();
  }
  /// The essential matrix's keyframe -> frame pose T_kf_frame (translation up to scale).
  std::optional<SE3d> EssentialPose(const ImageU8& keyframe, const ImageU8& frame) const {
    TwoViewBootstrap matcher(camera_, UpdateDirectionOptions{}.matcher);
    matcher.SetReference(keyframe);
    const std::optional<TwoViewPair> pair = matcher.TryFrame(frame);
    if (!pair) return std::nullopt;
    return pair->T_frame_ref.Inverse();
  }
  /// A tracked pose: the true rotation, and a 0.21 long translation turned `deg` degrees about
  /// the y axis from `direction`.
  static SE3d TrackedAt(const SE3d& T_true, const Eigen::Vector3d& direction, double deg) {
    return SE3d(T_true.Rotation(), SO3d::Exp(Eigen::Vector3d(0.0, deg / kRadToDeg, 0.0)) *
                                       direction.normalized() * 0.21);
  }
};

// 20 cm sideways and 5 cm forward with a 2 degree turn in a room 2-4 m deep. The essential
// matrix's own direction (TwoViewBootstrapTest checks its accuracy) is found with the same
// matcher; a tracked direction 2 degrees from it must come out halfway (weight 0.5) with the
// tracked rotation and length, and be left alone for a short baseline, another keyframe, or a
// tracked direction beyond the gate (max_angle_deg).
TEST_F(UpdateDirectionTest, BlendsTheTrackedDirectionWithTheEssentialMatrix) {
  const SE3d T_true(SO3d::Exp(Eigen::Vector3d(0.0, 2.0 / kRadToDeg, 0.0)),
                    Eigen::Vector3d(0.20, 0.0, 0.05));
  const ImageU8 keyframe = Render(SE3d()), frame = Render(T_true);
  const std::optional<Eigen::Vector3d> found = EssentialDirection(keyframe, frame);
  ASSERT_TRUE(found.has_value());
  const Eigen::Vector3d essential = *found;
  // Sanity only: on this weakly textured render the 800-feature direction is 5.4 degrees off
  // (11.9 with ORB positions and the 5-point model alone; the gate keeps such errors out).
  EXPECT_LT(AngleBetweenDeg(essential, T_true.Translation()), 8.0);
  const auto tracked_at = [&](double deg) { return TrackedAt(T_true, essential, deg); };

  UpdateDirectionOptions every_update;
  every_update.recheck_growth = 1.0;       // no reuse of a correction (tested below)
  every_update.max_axis_angle_deg = 90.0;  // this step is mostly sideways (tested below)
  every_update.blend_rotation = false;     // the direction alone (rotation: tested below)
  UpdateDirection direction(camera_, every_update);
  direction.SetKeyframe(3, keyframe);
  const SE3d T_tracked = tracked_at(2.0);
  const SE3d refined = direction.Refine(3, frame, T_tracked, 0.1);
  EXPECT_NEAR(AngleBetweenDeg(refined.Translation(), essential), 1.0, 0.01);
  EXPECT_NEAR(AngleBetweenDeg(refined.Translation(), T_tracked.Translation()), 1.0, 0.01);
  EXPECT_NEAR(refined.Translation().norm(), 0.21, 1e-12);
  EXPECT_EQ(refined.Rotation().UnitQuaternion().coeffs(),
            T_tracked.Rotation().UnitQuaternion().coeffs());

  const Eigen::Vector3d t = T_tracked.Translation();
  EXPECT_EQ(direction.Refine(3, frame, T_tracked, 0.01).Translation(), t);  // short baseline
  EXPECT_EQ(direction.Refine(4, frame, T_tracked, 0.1).Translation(), t);   // other keyframe
  const SE3d far_off = tracked_at(every_update.max_angle_deg + 2.0);
  EXPECT_EQ(direction.Refine(3, frame, far_off, 0.1).Translation(), far_off.Translation());
  direction.Reset();
  EXPECT_EQ(direction.Refine(3, frame, T_tracked, 0.1).Translation(), t);
}

TEST_F(UpdateDirectionTest, ReusesTheLastCorrectionBetweenChecks) {
  const SE3d T_true(SO3d(), Eigen::Vector3d(0.20, 0.0, 0.05));
  const ImageU8 keyframe = Render(SE3d()), frame = Render(T_true);
  const std::optional<Eigen::Vector3d> found = EssentialDirection(keyframe, frame);
  ASSERT_TRUE(found.has_value());
  const Eigen::Vector3d essential = *found;
  const auto tracked_at = [&](double deg) { return TrackedAt(T_true, essential, deg); };
  UpdateDirectionOptions options;  // recheck_growth 1.5, reuse within 5 degrees
  options.max_axis_angle_deg = 90.0;
  UpdateDirection direction(camera_, options);
  direction.SetKeyframe(3, keyframe);
  const SE3d checked = tracked_at(2.0);
  EXPECT_NEAR(AngleBetweenDeg(direction.Refine(3, frame, checked, 0.1).Translation(),
                              checked.Translation()),
              1.0,
              0.01);  // a check: halfway to the essential matrix
  // 1 degree further and a similar baseline: the same 1-degree correction, not a new check
  // (which would blend halfway from 3 degrees, i.e. move it by 1.5).
  const SE3d next = tracked_at(3.0);
  const Eigen::Vector3d reused = direction.Refine(3, frame, next, 0.11).Translation();
  EXPECT_NEAR(AngleBetweenDeg(reused, next.Translation()), 1.0, 0.01);
  EXPECT_NEAR(AngleBetweenDeg(reused, essential), 2.0, 0.01);
  EXPECT_NEAR(reused.norm(), 0.21, 1e-12);
  // The baseline grew beyond 1.5x: checked again, beyond the gate.
  const SE3d far_off = tracked_at(options.max_angle_deg + 2.0);
  EXPECT_EQ(direction.Refine(3, frame, far_off, 0.2).Translation(), far_off.Translation());
  // The check left no correction; a direction far from that one is checked again.
  const SE3d back = tracked_at(-1.0);
  EXPECT_NEAR(
      AngleBetweenDeg(direction.Refine(3, frame, back, 0.2).Translation(), back.Translation()), 0.5,
      0.01);
}

TEST_F(UpdateDirectionTest, SidewaysMotionIsNotChecked) {
  // 20 cm sideways, 5 cm forward: 76 degrees from the optical axis, beyond the default 45.
  // The same pair is blended once the limit is lifted, so only the limit leaves it alone.
  const SE3d T(SO3d(), Eigen::Vector3d(0.20, 0.0, 0.05));
  const ImageU8 keyframe = Render(SE3d()), frame = Render(T);
  const SE3d tracked(SO3d(), SO3d::Exp(Eigen::Vector3d(0.0, 0.02, 0.0)) * T.Translation());
  UpdateDirection by_default(camera_, {});
  by_default.SetKeyframe(3, keyframe);
  EXPECT_EQ(by_default.Refine(3, frame, tracked, 0.1).Translation(), tracked.Translation());
  UpdateDirectionOptions any_direction;
  any_direction.max_axis_angle_deg = 90.0;
  UpdateDirection lifted(camera_, any_direction);
  lifted.SetKeyframe(3, keyframe);
  EXPECT_NE(lifted.Refine(3, frame, tracked, 0.1).Translation(), tracked.Translation());
}

// In a turn tracking trades yaw against sideways translation; the check moves the rotation
// the same share (0.5) towards the essential matrix's as the direction, along the geodesic,
// and a reused correction carries the rotation's part too.
TEST_F(UpdateDirectionTest, BlendsTheRotationWithTheDirection) {
  const SE3d T_true(SO3d::Exp(Eigen::Vector3d(0.0, 2.0 / kRadToDeg, 0.0)),
                    Eigen::Vector3d(0.20, 0.0, 0.05));
  const ImageU8 keyframe = Render(SE3d()), frame = Render(T_true);
  const std::optional<SE3d> found = EssentialPose(keyframe, frame);
  ASSERT_TRUE(found.has_value());
  const SO3d R_essential = found->Rotation();
  EXPECT_LT((R_essential.Inverse() * T_true.Rotation()).Log().norm() * kRadToDeg, 1.0);
  // Tracked: 1 degree more yaw than the essential matrix, direction 2 degrees off.
  const auto tracked_at = [&](double deg) {
    const SE3d direction_only = TrackedAt(T_true, found->Translation(), deg);
    return SE3d(R_essential * SO3d::Exp(Eigen::Vector3d(0.0, 1.0 / kRadToDeg, 0.0)),
                direction_only.Translation());
  };
  const auto degrees = [](const SO3d& a, const SO3d& b) {
    return (a.Inverse() * b).Log().norm() * kRadToDeg;
  };
  UpdateDirectionOptions options;
  options.max_axis_angle_deg = 90.0;
  UpdateDirection direction(camera_, options);
  direction.SetKeyframe(3, keyframe);
  const SE3d tracked = tracked_at(2.0);
  const SE3d refined = direction.Refine(3, frame, tracked, 0.1);
  EXPECT_NEAR(degrees(refined.Rotation(), R_essential), 0.5, 1e-6);
  EXPECT_NEAR(degrees(refined.Rotation(), tracked.Rotation()), 0.5, 1e-6);
  EXPECT_NEAR(AngleBetweenDeg(refined.Translation(), tracked.Translation()), 1.0, 0.01);
  // Reused for the next frame (1 degree further, similar baseline): the same correction.
  const SE3d next(tracked.Rotation() * SO3d::Exp(Eigen::Vector3d(0.0, 0.2 / kRadToDeg, 0.0)),
                  tracked_at(3.0).Translation());
  const SE3d reused = direction.Refine(3, frame, next, 0.11);
  const SO3d correction = refined.Rotation() * tracked.Rotation().Inverse();
  EXPECT_LT(degrees(reused.Rotation(), correction * next.Rotation()), 1e-9);
  // Beyond the direction gate neither is touched.
  const SE3d far_off = tracked_at(options.max_angle_deg + 2.0);
  const SE3d kept = direction.Refine(3, frame, far_off, 0.2);
  EXPECT_EQ(kept.Rotation().UnitQuaternion().coeffs(),
            far_off.Rotation().UnitQuaternion().coeffs());
}

TEST_F(UpdateDirectionTest, DisabledLeavesThePoseAlone) {
  UpdateDirectionOptions options;
  options.enabled = false;
  UpdateDirection direction(camera_, options);
  direction.SetKeyframe(3, Render(SE3d()));
  const SE3d T(SO3d(), Eigen::Vector3d(0.0, 0.05, 0.25));
  EXPECT_EQ(direction.Refine(3, Render(T), T, 0.1).Translation(), T.Translation());
}

}  // namespace
}  // namespace parallax
