// Trajectory files: TUM, KITTI (with times), EuRoC data.csv; detection by content.
#include "fuzz_input.hpp"
#include "tools/dataset/groundtruth_files.hpp"
#include "tools/dataset/trajectory.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace parallax;
  const std::string path = fuzz::WriteInput("trajectory.txt", data, size);
  fuzz::Accepts([&] { ReadTumTrajectory(path); });
  fuzz::Accepts([&] { ReadTrajectoryFile({path, path, ""}); });  // KITTI: times from itself
  const std::string csv = fuzz::WriteInput("data.csv", data, size);
  fuzz::Accepts([&] { ReadTrajectoryFile({csv, "", ""}); });
  return 0;
}
