#pragma once
// Stamped pose sequences and their file formats (TUM read/write, KITTI write).

#include <string>
#include <vector>

#include "core/se3.hpp"

namespace parallax {

/// Camera-to-world pose T_w_c at a timestamp (seconds, as given by the input).
struct StampedPose {
  double timestamp = 0.0;
  SE3d T_w_c;
};

using Trajectory = std::vector<StampedPose>;

/// Reads a TUM trajectory: lines `timestamp tx ty tz qx qy qz qw`; '#' comments and blank
/// lines are skipped. Throws InputError naming file and line for a missing file, a malformed
/// line, a non-finite value, a zero quaternion, or timestamps that do not increase.
Trajectory ReadTumTrajectory(const std::string& path);

/// Writes TUM format. Timestamps are printed in the shortest form that reads back to the
/// same double (so "1305031102.175304" stays exactly that). Throws InputError if the file
/// cannot be written.
void WriteTumTrajectory(const std::string& path, const Trajectory& trajectory);

/// Writes KITTI format: one row-major 3x4 [R | t] (T_w_c) per line, no timestamps.
void WriteKittiTrajectory(const std::string& path, const Trajectory& trajectory);

/// Reads KITTI poses (12 numbers per line) with the given timestamps (same count).
Trajectory ReadKittiTrajectory(const std::string& path, const std::vector<double>& timestamps);

/// One line of each format (no newline).
std::string FormatTumLine(const StampedPose& pose);
std::string FormatKittiLine(const StampedPose& pose);

/// Shortest round-trip decimal form of a timestamp.
std::string FormatTimestamp(double seconds);

}  // namespace parallax
