#pragma once
// The PNGs camera sequences come in (8-bit grey or RGB, not interlaced, no colour
// management), decoded without libpng: the whole file is read at once, the IDAT stream
// inflated by libdeflate and the rows unfiltered here, where libpng goes through zlib and
// its row pipeline at about twice the cost (docs/benchmarks.md, "Decoding PNG frames").
// The pixels are libpng's for OpenCV's IMREAD_GRAYSCALE (tests/tools/png_direct_test.cpp
// compares them); every other PNG, and every file with anything unexpected in it, is left
// to libpng (tools/dataset/png_codec.cpp), which decodes it or refuses it with its own
// message.

#include <cstddef>
#include <cstdint>
#include <opencv2/core.hpp>
#include <optional>

namespace parallax::codecs {

/// libpng's integer weights (out of 32768) for OpenCV's png_set_rgb_to_gray(0.299, 0.587):
/// red and green truncated from PNG fixed point (1e-5), blue the rest.
inline constexpr std::uint32_t kPngGreyRed = 29900U * 32768U / 100000U;
inline constexpr std::uint32_t kPngGreyGreen = 58700U * 32768U / 100000U;
inline constexpr std::uint32_t kPngGreyBlue = 32768U - kPngGreyRed - kPngGreyGreen;

/// Decodes `size` bytes of a whole PNG file into 8-bit grey (RGB converted as libpng's
/// 8-bit rgb_to_gray without gamma does: a grey pixel stays, others get the weighted sum,
/// truncated). Handled: bit depth 8, colour type grey (0) or RGB (2), no interlacing, chunks
/// IHDR, IDAT, IEND and text, time or physical-size chunks only, every CRC and the zlib
/// checksum right, no more than `max_pixels` pixels. std::nullopt for anything else.
std::optional<cv::Mat> DecodeCommonPng(const std::uint8_t* bytes, std::size_t size,
                                       long long max_pixels);

/// One row of PNG filter reversal (PNG specification section 9): `filtered` (without its
/// filter-type byte) with the reconstructed `previous` row (zeros for the first) into `row`;
/// `bytes_per_pixel` 1 or 3. False for a filter type above 4.
bool UnfilterPngRow(int filter_type, const std::uint8_t* filtered, const std::uint8_t* previous,
                    std::size_t row_bytes, int bytes_per_pixel, std::uint8_t* row);

}  // namespace parallax::codecs
