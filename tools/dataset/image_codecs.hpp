#pragma once
// The PNG (libpng) and JPEG (libjpeg) codecs behind tools/dataset/image_file.hpp. Each
// reproduces what OpenCV 4's imread does with the same library for the same mode, so the
// pixels are the same as before (tests/tools/image_file_test.cpp compares them).

#include <opencv2/core.hpp>
#include <string>

#include "tools/dataset/image_file.hpp"

namespace parallax::codecs {

/// What a decoder reports besides the pixels.
enum class DecodeStatus {
  kOk,
  kFailed,      ///< corrupt, truncated or too large: `message` says why
  kNotHandled,  ///< valid but outside what this decoder reproduces (the media module does)
};

struct DecodeResult {
  DecodeStatus status = DecodeStatus::kFailed;
  cv::Mat pixels;       ///< set when kOk and the whole image was asked for
  std::string message;  ///< why, when not kOk
};

/// Which decoders DecodePng may use.
enum class PngDecoders {
  kDirectFirst,  ///< the direct decoder for the PNGs it handles (png_direct.hpp), else libpng
  kLibpngOnly,   ///< libpng for every file (tests and benchmarks compare the two)
};

/// Decodes a PNG file. With `size_only` set, reads the header only: the size goes there and
/// `pixels` stays empty.
DecodeResult DecodePng(const std::string& path, ImageReadMode mode, long long max_pixels,
                       cv::Size* size_only, PngDecoders decoders = PngDecoders::kDirectFirst);

/// Decodes a JPEG file; kNotHandled for CMYK, an Exif block (OpenCV rotates by its
/// orientation) and Motion-JPEG frames without Huffman tables.
DecodeResult DecodeJpeg(const std::string& path, ImageReadMode mode, long long max_pixels,
                        cv::Size* size_only);

/// Writes an 8/16-bit, 1- or 3-channel (BGR) matrix as PNG; false with `message` on failure.
bool EncodePng(const std::string& path, const cv::Mat& image, int level, std::string* message);

}  // namespace parallax::codecs
