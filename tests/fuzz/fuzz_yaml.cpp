// The YAML inputs: calibration files, pipeline options (--config) and benchmark suites.
#include "fuzz_input.hpp"
#include "tools/bench/suite.hpp"
#include "tools/config_yaml.hpp"
#include "tools/dataset/calibration_yaml.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace parallax;
  const std::string path = fuzz::WriteInput("input.yaml", data, size);
  fuzz::Accepts([&] { ReadCalibrationYaml(path); });
  fuzz::Accepts([&] {
    SystemOptions options;
    ApplyConfigYaml(path, &options);
  });
  fuzz::Accepts([&] { bench::ReadSuite(path, (fuzz::Scratch() / "cache").string()); });
  return 0;
}
