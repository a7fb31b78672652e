#include "tools/dataset/png_direct.hpp"

#include <libdeflate.h>

#include <algorithm>
#include <array>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <vector>

namespace parallax::codecs {
namespace {

constexpr std::array<std::uint8_t, 8> kSignature = {0x89, 'P', 'N', 'G', 0x0d, 0x0a, 0x1a, 0x0a};
constexpr std::uint32_t kMaxSide = 1U << 20;  // as png_codec.cpp's bound

std::uint32_t BigEndian32(const std::uint8_t* p) {
  return (std::uint32_t{p[0]} << 24) | (std::uint32_t{p[1]} << 16) | (std::uint32_t{p[2]} << 8) |
         std::uint32_t{p[3]};
}

bool ChunkIs(const std::uint8_t* type, const char* name) { return std::memcmp(type, name, 4) == 0; }

/// Ancillary chunks that change no pixel of a grey or RGB image read as grey (gAMA, cHRM,
/// sRGB, iCCP, sBIT, tRNS and bKGD could, and are left to libpng with everything else).
bool HarmlessAncillary(const std::uint8_t* type) {
  for (const char* name : {"tEXt", "zTXt", "iTXt", "tIME", "pHYs"}) {
    if (ChunkIs(type, name)) return true;
  }
  return false;
}

struct Header {
  std::uint32_t width = 0;
  std::uint32_t height = 0;
  int channels = 0;  ///< 1 grey, 3 RGB
};

std::optional<Header> ReadHeader(const std::uint8_t* data, std::uint32_t length,
                                 long long max_pixels) {
  if (length != 13) return std::nullopt;
  Header h{BigEndian32(data), BigEndian32(data + 4), 0};
  const int bit_depth = data[8], colour_type = data[9];
  const bool plain =
      data[10] == 0 && data[11] == 0 && data[12] == 0;  // deflate, filters, no interlace
  if (bit_depth != 8 || !plain || (colour_type != 0 && colour_type != 2)) return std::nullopt;
  if (h.width == 0 || h.height == 0 || h.width > kMaxSide || h.height > kMaxSide ||
      static_cast<long long>(h.width) * h.height > max_pixels) {
    return std::nullopt;  // libpng's path words the refusal
  }
  h.channels = colour_type == 2 ? 3 : 1;
  return h;
}

struct DecompressorDeleter {
  void operator()(libdeflate_decompressor* d) const { libdeflate_free_decompressor(d); }
};

/// Per thread: the decompressor and the buffers, reused frame after frame.
struct Scratch {
  std::unique_ptr<libdeflate_decompressor, DecompressorDeleter> inflater{
      libdeflate_alloc_decompressor()};
  std::vector<std::uint8_t> compressed;
  std::vector<std::uint8_t> inflated;
  std::vector<std::uint8_t> rows;  ///< RGB: two reconstructed rows; grey: the zero row
};

Scratch& ThreadScratch() {
  thread_local Scratch scratch;
  return scratch;
}

/// Walks the chunks after the signature; gathers the IDAT stream. False on anything but a
/// well-formed IHDR, IDAT..., IEND sequence with right CRCs and harmless extras.
bool GatherChunks(const std::uint8_t* bytes, std::size_t size, long long max_pixels, Header* header,
                  std::vector<std::uint8_t>* compressed) {
  compressed->clear();
  std::size_t at = kSignature.size();
  bool have_header = false;
  while (at + 12 <= size) {
    const std::uint32_t length = BigEndian32(bytes + at);
    if (length > size - at - 12) return false;  // truncated (or above 2^31)
    const std::uint8_t* type = bytes + at + 4;
    const std::uint8_t* data = type + 4;
    const std::uint32_t crc = BigEndian32(data + length);
    if (libdeflate_crc32(0, type, std::size_t{length} + 4) != crc) return false;
    at += std::size_t{length} + 12;
    if (!have_header) {
      if (!ChunkIs(type, "IHDR")) return false;
      const std::optional<Header> h = ReadHeader(data, length, max_pixels);
      if (!h) return false;
      *header = *h;
      have_header = true;
    } else if (ChunkIs(type, "IDAT")) {
      compressed->insert(compressed->end(), data, data + length);
    } else if (ChunkIs(type, "IEND")) {
      return !compressed->empty();
    } else if (!HarmlessAncillary(type)) {
      return false;
    }
  }
  return false;  // no IEND
}

/// The weighted sum libpng's 8-bit rgb_to_gray computes without gamma tables (truncated;
/// a pixel with equal channels is copied).
void RgbRowToGrey(const std::uint8_t* rgb, std::uint32_t width, std::uint8_t* grey) {
  for (std::uint32_t x = 0; x < width; ++x) {
    const std::uint32_t r = rgb[3 * x], g = rgb[3 * x + 1], b = rgb[3 * x + 2];
    grey[x] = (r == g && r == b)
                  ? static_cast<std::uint8_t>(r)
                  : static_cast<std::uint8_t>(
                        (kPngGreyRed * r + kPngGreyGreen * g + kPngGreyBlue * b) >> 15);
  }
}

/// The Paeth predictor (PNG specification 9.4) as selections, not branches: in a grey row
/// each byte waits for the one before it, and mispredicted branches made it the decoder's
/// slowest step. a wins ties, then b (the specification's order).
std::uint8_t Paeth(int a, int b, int c) {
  const int p = b - c, q = a - c;
  const int pa = std::abs(p), pb = std::abs(q), pc = std::abs(p + q);
  const int ab = pb < pa ? b : a;
  const int best = pb < pa ? pb : pa;
  return static_cast<std::uint8_t>(pc < best ? c : ab);
}

}  // namespace

bool UnfilterPngRow(int filter_type, const std::uint8_t* filtered, const std::uint8_t* previous,
                    std::size_t row_bytes, int bytes_per_pixel, std::uint8_t* row) {
  const auto bpp = static_cast<std::size_t>(bytes_per_pixel);
  const std::size_t lead = std::min(bpp, row_bytes);  // bytes with no left neighbour
  switch (filter_type) {
    case 0:  // none
      std::memcpy(row, filtered, row_bytes);
      return true;
    case 1:  // sub
      std::memcpy(row, filtered, lead);
      for (std::size_t i = bpp; i < row_bytes; ++i) {
        row[i] = static_cast<std::uint8_t>(filtered[i] + row[i - bpp]);
      }
      return true;
    case 2:  // up
      for (std::size_t i = 0; i < row_bytes; ++i) {
        row[i] = static_cast<std::uint8_t>(filtered[i] + previous[i]);
      }
      return true;
    case 3:  // average
      for (std::size_t i = 0; i < lead; ++i) {
        row[i] = static_cast<std::uint8_t>(filtered[i] + (previous[i] >> 1));
      }
      for (std::size_t i = bpp; i < row_bytes; ++i) {
        row[i] = static_cast<std::uint8_t>(filtered[i] + ((row[i - bpp] + previous[i]) >> 1));
      }
      return true;
    case 4:  // Paeth
      for (std::size_t i = 0; i < lead; ++i) {
        row[i] = static_cast<std::uint8_t>(filtered[i] + previous[i]);  // a = c = 0
      }
      for (std::size_t i = bpp; i < row_bytes; ++i) {
        row[i] = static_cast<std::uint8_t>(filtered[i] +
                                           Paeth(row[i - bpp], previous[i], previous[i - bpp]));
      }
      return true;
    default:
      return false;
  }
}

std::optional<cv::Mat> DecodeCommonPng(const std::uint8_t* bytes, std::size_t size,
                                       long long max_pixels) {
  if (size < kSignature.size() || !std::equal(kSignature.begin(), kSignature.end(), bytes)) {
    return std::nullopt;
  }
  Scratch& s = ThreadScratch();
  if (!s.inflater) return std::nullopt;
  Header h;
  if (!GatherChunks(bytes, size, max_pixels, &h, &s.compressed)) return std::nullopt;
  const std::size_t row_bytes = std::size_t{h.width} * static_cast<std::size_t>(h.channels);
  const std::size_t expected = (row_bytes + 1) * h.height;
  s.inflated.resize(expected);
  std::size_t inflated_bytes = 0;
  if (libdeflate_zlib_decompress(s.inflater.get(), s.compressed.data(), s.compressed.size(),
                                 s.inflated.data(), expected,
                                 &inflated_bytes) != LIBDEFLATE_SUCCESS ||
      inflated_bytes != expected) {
    return std::nullopt;  // corrupt, or more or less data than the rows need
  }
  cv::Mat grey(static_cast<int>(h.height), static_cast<int>(h.width), CV_8UC1);
  // Grey rows are reconstructed in place in the output; RGB rows in two scratch rows.
  const bool rgb = h.channels == 3;
  // The row before the first is zeros (for grey, the only scratch row).
  s.rows.assign(rgb ? 2 * row_bytes : row_bytes, 0);
  const std::uint8_t* previous = s.rows.data() + (rgb ? row_bytes : 0);
  for (std::uint32_t y = 0; y < h.height; ++y) {
    const std::uint8_t* line = s.inflated.data() + y * (row_bytes + 1);
    std::uint8_t* row =
        rgb ? s.rows.data() + (y % 2) * row_bytes : grey.ptr<std::uint8_t>(static_cast<int>(y));
    if (!UnfilterPngRow(line[0], line + 1, previous, row_bytes, h.channels, row)) {
      return std::nullopt;
    }
    if (rgb) RgbRowToGrey(row, h.width, grey.ptr<std::uint8_t>(static_cast<int>(y)));
    previous = row;
  }
  return grey;
}

}  // namespace parallax::codecs
