#pragma once
// Whole-file binary reading and atomic writing (temporary file in the same folder + rename,
// so a reader never sees a half-written file and a failed write leaves the old one).

#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace parallax {

/// The file's bytes; throws std::runtime_error naming the path when it cannot be read.
std::vector<std::uint8_t> ReadBinaryFile(const std::string& path);

/// Writes `bytes` to `path` atomically; throws std::runtime_error naming the path on failure
/// (the temporary file is removed).
void WriteBinaryFileAtomically(const std::string& path, std::span<const std::uint8_t> bytes);

}  // namespace parallax
