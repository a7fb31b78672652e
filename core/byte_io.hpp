#pragma once
// Little-endian binary writing and bounds-checked reading for the files Parallax writes
// (vocabulary, maps). Readers throw with the source name and byte offset of the problem.

#include <algorithm>
#include <bit>
#include <cstdint>
#include <cstring>
#include <span>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

#include "core/crc32.hpp"

namespace parallax {

static_assert(std::endian::native == std::endian::little,
              "binary files are little-endian; a big-endian host needs byte swapping here");

/// Appends values in their little-endian representation.
class ByteWriter {
 public:
  template <typename T>
  void Put(const T& value) {
    static_assert(std::is_trivially_copyable_v<T>);
    const auto* p = reinterpret_cast<const std::uint8_t*>(&value);
    bytes_.insert(bytes_.end(), p, p + sizeof(T));
  }
  void PutBytes(std::span<const std::uint8_t> bytes) {
    bytes_.insert(bytes_.end(), bytes.begin(), bytes.end());
  }
  const std::vector<std::uint8_t>& Bytes() const { return bytes_; }
  std::vector<std::uint8_t> Take() { return std::move(bytes_); }

 private:
  std::vector<std::uint8_t> bytes_;
};

/// Reads values in order; any read past the end throws Error (a std::runtime_error subclass
/// chosen by the caller) naming the source and the offset.
template <typename Error>
class ByteReader {
 public:
  ByteReader(std::span<const std::uint8_t> bytes, std::string source)
      : bytes_(bytes), source_(std::move(source)) {}

  template <typename T>
  T Get(const char* what) {
    static_assert(std::is_trivially_copyable_v<T>);
    Require(sizeof(T), what);
    T value;
    std::memcpy(&value, bytes_.data() + offset_, sizeof(T));
    offset_ += sizeof(T);
    return value;
  }
  void GetBytes(void* out, std::size_t n, const char* what) {
    Require(n, what);
    if (n > 0) std::memcpy(out, bytes_.data() + offset_, n);
    offset_ += n;
  }
  /// The header of a Parallax binary file: `magic`, a CRC-32 of everything before the
  /// last four bytes (checked first, so that corruption reads as corruption), and a u32
  /// format version that must equal `version`. `kind` names the file kind in messages.
  void ReadHeader(std::span<const char> magic, const std::string& kind, std::uint32_t version) {
    std::vector<char> found(magic.size());
    GetBytes(found.data(), found.size(), "magic");
    if (!std::equal(found.begin(), found.end(), magic.begin())) Fail("not a Parallax " + kind);
    std::uint32_t stored = 0;
    std::memcpy(&stored, bytes_.data() + bytes_.size() - 4, 4);  // the magic is longer
    if (stored != Crc32(bytes_.first(bytes_.size() - 4))) {
      Fail("checksum mismatch (the file is corrupt or truncated)");
    }
    const auto found_version = Get<std::uint32_t>("format version");
    if (found_version != version) {
      Fail("format version " + std::to_string(found_version) + " (this build reads " +
           std::to_string(version) + ")");
    }
  }
  std::size_t Offset() const { return offset_; }
  std::size_t Remaining() const { return bytes_.size() - offset_; }
  /// Throws Error("<source>: byte <offset>: <message>").
  [[noreturn]] void Fail(const std::string& message) const {
    throw Error(source_ + ": byte " + std::to_string(offset_) + ": " + message);
  }

 private:
  void Require(std::size_t n, const char* what) const {
    if (n > bytes_.size() - offset_) {
      Fail(std::string("truncated (") + what + " needs " + std::to_string(n) + " bytes, " +
           std::to_string(bytes_.size() - offset_) + " left)");
    }
  }

  std::span<const std::uint8_t> bytes_;
  std::string source_;
  std::size_t offset_ = 0;
};

}  // namespace parallax
