// Trajectory files: TUM round trip, exact timestamps, KITTI output, malformed input.

#include "tools/dataset/trajectory.hpp"

#include <gtest/gtest.h>

#include "tests/tools/temp_dir.hpp"
#include "tools/dataset/input_error.hpp"

namespace parallax {
namespace {

using test::TempDir;

TEST(Trajectory, TumRoundTripKeepsTimestampsExactly) {
  TempDir dir;
  Trajectory trajectory;
  for (int i = 0; i < 5; ++i) {
    const double t = 1305031102.175304 + 0.033 * i;
    trajectory.push_back(
        {t, SE3d::Exp((Eigen::Matrix<double, 6, 1>() << 0.1 * i, -0.2, 0.3, 0.01 * i, 0.2, -0.1)
                          .finished())});
  }
  WriteTumTrajectory(dir.File("t.txt"), trajectory);
  const Trajectory back = ReadTumTrajectory(dir.File("t.txt"));
  ASSERT_EQ(back.size(), trajectory.size());
  for (std::size_t i = 0; i < back.size(); ++i) {
    EXPECT_EQ(back[i].timestamp, trajectory[i].timestamp);  // bit-exact
    EXPECT_TRUE(back[i].T_w_c.Matrix().isApprox(trajectory[i].T_w_c.Matrix(), 1e-8));
  }
  EXPECT_EQ(FormatTimestamp(1305031102.175304), "1305031102.175304");
}

TEST(Trajectory, MalformedLinesNameFileAndLine) {
  TempDir dir;
  const std::string file = dir.Write("bad.txt", "# header\n1.0 0 0 0 0 0 0 1\n2.0 0 0 x 0 0 0 1\n");
  try {
    ReadTumTrajectory(file);
    FAIL() << "malformed line accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(e.Line(), 3);
    EXPECT_NE(std::string(e.what()).find(file + ":3"), std::string::npos) << e.what();
  }
  EXPECT_THROW(ReadTumTrajectory(dir.Write("short.txt", "1.0 0 0 0 0 0 1\n")), InputError);
  EXPECT_THROW(ReadTumTrajectory(dir.Write("order.txt", "2.0 0 0 0 0 0 0 1\n1.0 0 0 0 0 0 0 1\n")),
               InputError);
  EXPECT_THROW(ReadTumTrajectory(dir.Write("zeroq.txt", "1.0 0 0 0 0 0 0 0\n")), InputError);
  EXPECT_THROW(ReadTumTrajectory(dir.File("missing.txt")), InputError);
}

TEST(Trajectory, KittiWriteReadRoundTrip) {
  TempDir dir;
  Trajectory trajectory = {
      {0.0, SE3d()}, {0.1, SE3d(SO3d::Exp(Eigen::Vector3d(0, 0.3, 0)), Eigen::Vector3d(1, 2, 3))}};
  WriteKittiTrajectory(dir.File("k.txt"), trajectory);
  const Trajectory back = ReadKittiTrajectory(dir.File("k.txt"), {0.0, 0.1});
  ASSERT_EQ(back.size(), 2u);
  EXPECT_TRUE(back[1].T_w_c.Matrix().isApprox(trajectory[1].T_w_c.Matrix(), 1e-8));
  EXPECT_THROW(ReadKittiTrajectory(dir.File("k.txt"), {0.0}), InputError);
}

}  // namespace
}  // namespace parallax
