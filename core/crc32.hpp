#pragma once
// CRC-32 (IEEE 802.3, reflected polynomial 0xEDB88320, as zlib and PNG): checksums of the
// binary files Parallax writes (vocabulary, maps).

#include <cstdint>
#include <span>

namespace parallax {

/// CRC-32 of `bytes`, continuing from `crc` (0 to start): Crc32(b, Crc32(a)) == Crc32(a + b).
std::uint32_t Crc32(std::span<const std::uint8_t> bytes, std::uint32_t crc = 0);

}  // namespace parallax
