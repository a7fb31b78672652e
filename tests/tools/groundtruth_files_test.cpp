// Ground truth read directly in each benchmark's format, and coverage against image frames.

#include "tools/dataset/groundtruth_files.hpp"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

#include "temp_dir.hpp"
#include "tools/dataset/input_error.hpp"
#include "tools/eval/evaluation.hpp"

namespace parallax {
namespace {

using test::SharedDataDir;
using test::TempDir;

Trajectory Wiggle(int n) {
  Trajectory t;
  for (int i = 0; i < n; ++i) {
    const double a = 0.05 * i;
    t.push_back({0.1 * i, SE3d(SO3d::Exp(Eigen::Vector3d(0.1 * std::sin(a), a, 0.02 * i)),
                               Eigen::Vector3d(std::sin(a), 0.1 * i, std::cos(a)))});
  }
  return t;
}

TEST(GroundTruthFiles, KittiPosesWithTimesMatchTheirTumConversion) {
  const TempDir dir;
  const Trajectory truth = Wiggle(30);
  dir.Write("poses/placeholder", "");
  WriteKittiTrajectory(dir.File("poses/07.txt"), truth);
  std::string times;
  for (const StampedPose& p : truth) times += FormatTimestamp(p.timestamp) + "\n";
  dir.Write("sequences/07/times.txt", times);
  EXPECT_EQ(DetectTrajectoryFormat(dir.File("poses/07.txt")), TrajectoryFileFormat::kKitti);
  // times.txt found where the KITTI layout puts it.
  const Trajectory direct = ReadTrajectoryFile({dir.File("poses/07.txt"), "", ""});
  WriteTumTrajectory(dir.File("gt_tum.txt"), direct);
  const Trajectory converted = ReadTrajectoryFile({dir.File("gt_tum.txt"), "", ""});
  ASSERT_EQ(direct.size(), truth.size());
  Trajectory estimate = truth;
  for (std::size_t i = 0; i < estimate.size(); ++i) {
    estimate[i].T_w_c =
        SE3d(estimate[i].T_w_c.Rotation(),
             estimate[i].T_w_c.Translation() +
                 0.01 * std::sin(3.0 * static_cast<double>(i)) * Eigen::Vector3d::UnitX());
  }
  const double a = Evaluate(estimate, direct, {}).ate.rmse;
  const double b = Evaluate(estimate, converted, {}).ate.rmse;
  EXPECT_GT(a, 1e-3);
  EXPECT_NEAR(a, b, 1e-9);
  // Without times.txt: a clear error.
  const TempDir bare;
  WriteKittiTrajectory(bare.File("poses.txt"), truth);
  EXPECT_THROW(ReadTrajectoryFile({bare.File("poses.txt"), "", ""}), InputError);
}

TEST(GroundTruthFiles, EurocBodyPosesGetTheCameraExtrinsics) {
  const TempDir dir;
  // Camera 10 cm along the body's x axis, rotated 90 degrees about z.
  dir.Write("mav0/cam0/sensor.yaml",
            "%YAML:1.0\nsensor_type: camera\nT_BS:\n  cols: 4\n  rows: 4\n  data: [0, -1, 0, "
            "0.1, 1, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]\nrate_hz: 20\nresolution: [752, 480]\n"
            "camera_model: pinhole\nintrinsics: [458.6, 457.3, 367.2, 248.4]\n"
            "distortion_model: radial-tangential\ndistortion_coefficients: [0, 0, 0, 0]\n");
  const Trajectory body = Wiggle(20);
  std::string csv =
      "#timestamp, p_RS_R_x [m], p_RS_R_y [m], p_RS_R_z [m], q_RS_w [], q_RS_x [], "
      "q_RS_y [], q_RS_z [], v...\n";
  for (const StampedPose& p : body) {
    const Eigen::Quaterniond& q = p.T_w_c.Rotation().UnitQuaternion();
    const Eigen::Vector3d& t = p.T_w_c.Translation();
    csv += fmt::format("{},{},{},{},{},{},{},{},0,0,0\n",
                       static_cast<long long>(std::llround(p.timestamp * 1e9)), t.x(), t.y(), t.z(),
                       q.w(), q.x(), q.y(), q.z());
  }
  const std::string file = dir.Write("mav0/state_groundtruth_estimate0/data.csv", csv);
  EXPECT_EQ(DetectTrajectoryFormat(file), TrajectoryFileFormat::kEuroc);
  const Trajectory camera = ReadTrajectoryFile({file, "", ""});  // sensor.yaml found
  ASSERT_EQ(camera.size(), body.size());
  Eigen::Matrix4d M;
  M << 0, -1, 0, 0.1, 1, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1;
  const SE3d T_B_S(M);
  for (std::size_t i = 0; i < body.size(); ++i) {
    const SE3d expected = body[i].T_w_c * T_B_S;
    EXPECT_LT((camera[i].T_w_c.Translation() - expected.Translation()).norm(), 1e-6);
    EXPECT_LT((camera[i].T_w_c.Rotation().Inverse() * expected.Rotation()).Log().norm(), 1e-6);
    EXPECT_NEAR(camera[i].timestamp, body[i].timestamp, 1e-9);
  }
  EXPECT_THROW(ReadTrajectoryFile({dir.Write("x/data.csv", csv), "", ""}), InputError);
}

TEST(GroundTruthFiles, CoverageCountsImageFramesNotGroundTruthPoses) {
  // Ground truth at 100 Hz, images at 25 Hz, an estimate for 3 of every 4 images.
  Trajectory gt, estimate;
  std::vector<double> frames;
  for (int i = 0; i < 400; ++i)
    gt.push_back({0.01 * i, SE3d(SO3d(), Eigen::Vector3d(0.01 * i, std::sin(0.02 * i), 0))});
  for (int k = 0; k < 100; ++k) {
    frames.push_back(0.04 * k);
    if (k % 4 != 3) estimate.push_back({0.04 * k, gt[4 * static_cast<std::size_t>(k)].T_w_c});
  }
  EvaluationOptions options;
  EXPECT_LT(Evaluate(estimate, gt, options).coverage, 0.3);  // against the 100 Hz poses
  options.frame_timestamps = frames;
  const EvaluationReport r = Evaluate(estimate, gt, options);
  EXPECT_EQ(r.frames, 100u);
  EXPECT_EQ(r.frames_with_pose, 75u);
  EXPECT_DOUBLE_EQ(r.coverage, 0.75);
  EXPECT_GT(r.rpe_per_distance.translation.count, 0u);
  EXPECT_LT(r.rpe_per_distance.translation.rmse, 1e-9);  // a perfect estimate
}

TEST(GroundTruthFiles, SharedKittiClipDirectlyAndThroughItsFolder) {
  if (SharedDataDir().empty()) GTEST_SKIP() << "../shared/data is absent";
  const std::string root = SharedDataDir() + "/kitti_odometry_07_first160";
  const Trajectory poses = ReadTrajectoryFile({root + "/poses/07.txt", "", ""});
  const DatasetGroundTruth folder = ReadDatasetGroundTruth(root);
  ASSERT_EQ(poses.size(), 160u);
  ASSERT_EQ(folder.poses.size(), 160u);
  EXPECT_EQ(folder.frame_timestamps.size(), 160u);
  for (std::size_t i = 0; i < poses.size(); ++i) {
    EXPECT_EQ(poses[i].timestamp, folder.poses[i].timestamp);
    EXPECT_LT((poses[i].T_w_c.Translation() - folder.poses[i].T_w_c.Translation()).norm(), 1e-12);
  }
}

TEST(GroundTruthFiles, UnknownLayoutsAreNamed) {
  const TempDir dir;
  try {
    DetectTrajectoryFormat(dir.Write("odd.txt", "# comment\n1 2 3 4 5\n"));
    ADD_FAILURE();
  } catch (const InputError& e) {
    EXPECT_EQ(e.Line(), 2);
    EXPECT_NE(std::string(e.what()).find("5 fields"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace parallax
