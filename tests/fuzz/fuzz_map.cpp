// Map files (binary, checksummed). Input whose first byte is odd gets a valid CRC-32 appended
// to the rest, so that mutations reach the content checks behind the checksum; even: the
// bytes as they are. Corrupt input must be rejected with MapFileError, never crash or
// allocate without bound.
#include <vector>

#include "backend/map_file.hpp"
#include "core/crc32.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace parallax;
  if (size == 0) return 0;
  std::vector<std::uint8_t> bytes(data + 1, data + size);
  if ((data[0] & 1) != 0) {
    const std::uint32_t crc = Crc32(bytes);
    const auto* p = reinterpret_cast<const std::uint8_t*>(&crc);
    bytes.insert(bytes.end(), p, p + sizeof(crc));
  }
  try {
    DecodeMap(bytes, "fuzz.pxmap");
  } catch (const MapFileError&) {  // the only way to refuse a map (it names file and byte)
  }
  return 0;
}
