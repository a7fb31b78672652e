#include "tools/dataset/trajectory.hpp"

#include <fmt/format.h>

#include <cmath>
#include <fstream>
#include <sstream>

#include "tools/dataset/input_error.hpp"
#include "tools/dataset/text_lines.hpp"

namespace parallax {

Trajectory ReadTumTrajectory(const std::string& path) {
  Trajectory trajectory;
  ForEachDataLine(path, [&](const std::string& line, int line_number) {
    const std::vector<double> v = ParseNumbers(line, path, line_number, 8);
    const Eigen::Quaterniond q(v[7], v[4], v[5], v[6]);
    if (q.norm() < 1e-6) throw InputError(path, line_number, "quaternion has zero norm");
    if (!trajectory.empty() && !(v[0] > trajectory.back().timestamp)) {
      throw InputError(path, line_number, "timestamps must increase");
    }
    trajectory.push_back({v[0], SE3d(SO3d(q), Eigen::Vector3d(v[1], v[2], v[3]))});
  });
  return trajectory;
}

std::string FormatTimestamp(double seconds) { return fmt::format("{}", seconds); }

std::string FormatTumLine(const StampedPose& pose) {
  const Eigen::Vector3d& t = pose.T_w_c.Translation();
  const Eigen::Quaterniond& q = pose.T_w_c.Rotation().UnitQuaternion();
  return fmt::format("{} {:.9f} {:.9f} {:.9f} {:.9f} {:.9f} {:.9f} {:.9f}",
                     FormatTimestamp(pose.timestamp), t.x(), t.y(), t.z(), q.x(), q.y(), q.z(),
                     q.w());
}

std::string FormatKittiLine(const StampedPose& pose) {
  const Eigen::Matrix4d T = pose.T_w_c.Matrix();
  std::string line;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 4; ++c) {
      if (r > 0 || c > 0) line += ' ';
      line += fmt::format("{:.9e}", T(r, c));
    }
  }
  return line;
}

void WriteTumTrajectory(const std::string& path, const Trajectory& trajectory) {
  std::ofstream out(path);
  if (!out) throw InputError(path, "cannot open for writing");
  for (const StampedPose& pose : trajectory) out << FormatTumLine(pose) << '\n';
  if (!out) throw InputError(path, "write failed");
}

void WriteKittiTrajectory(const std::string& path, const Trajectory& trajectory) {
  std::ofstream out(path);
  if (!out) throw InputError(path, "cannot open for writing");
  for (const StampedPose& pose : trajectory) out << FormatKittiLine(pose) << '\n';
  if (!out) throw InputError(path, "write failed");
}

Trajectory ReadKittiTrajectory(const std::string& path, const std::vector<double>& timestamps) {
  Trajectory trajectory;
  ForEachDataLine(path, [&](const std::string& line, int line_number) {
    const std::vector<double> v = ParseNumbers(line, path, line_number, 12);
    if (trajectory.size() >= timestamps.size()) {
      throw InputError(path, line_number,
                       "more poses than timestamps (" + std::to_string(timestamps.size()) + ")");
    }
    Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
    for (int i = 0; i < 12; ++i) T(i / 4, i % 4) = v[static_cast<std::size_t>(i)];
    try {
      // Rotations in KITTI files carry ~1e-6 rounding; re-orthonormalise before checking.
      Eigen::Matrix3d R = T.topLeftCorner<3, 3>();
      const Eigen::Quaterniond q(R);
      trajectory.push_back({timestamps[trajectory.size()],
                            SE3d(SO3d(q), Eigen::Vector3d(T.topRightCorner<3, 1>()))});
      if ((trajectory.back().T_w_c.RotationMatrix() - R).cwiseAbs().maxCoeff() > 1e-3) {
        throw std::invalid_argument("rotation block is not a rotation");
      }
    } catch (const std::invalid_argument& e) {
      throw InputError(path, line_number, e.what());
    }
  });
  if (trajectory.size() != timestamps.size()) {
    throw InputError(path, "has " + std::to_string(trajectory.size()) + " poses but there are " +
                               std::to_string(timestamps.size()) + " timestamps");
  }
  return trajectory;
}

}  // namespace parallax
