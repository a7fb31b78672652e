#pragma once
// Shared by the fuzz targets: the input bytes as a file (every reader takes a path), and the
// rule that a reader may reject input only with an exception, never crash or hang.

#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>

namespace parallax::fuzz {

/// A private scratch folder for this process (libFuzzer runs one input at a time per process).
inline const std::filesystem::path& Scratch() {
  static const std::filesystem::path dir = [] {
    auto p = std::filesystem::temp_directory_path() / ("parallax_fuzz_" + std::to_string(getpid()));
    std::filesystem::create_directories(p);
    return p;
  }();
  return dir;
}

inline std::string WriteInput(const std::string& name, const std::uint8_t* data, std::size_t size) {
  const auto path = Scratch() / name;
  std::filesystem::create_directories(path.parent_path());
  std::ofstream(path, std::ios::binary)
      .write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  return path.string();
}

/// Runs `read`; any std::exception is an accepted rejection (bad input gets a message).
template <typename Read>
void Accepts(Read read) {
  try {
    read();
  } catch (const std::exception&) {
  }
}

}  // namespace parallax::fuzz
