#include "tools/dataset/image_file.hpp"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <initializer_list>

#include "tools/dataset/image_codecs.hpp"
#include "tools/dataset/input_error.hpp"
#include "tools/dataset/media_module.hpp"

namespace parallax {
namespace {

enum class FileKind { kPng, kJpeg, kOther };

/// The format from the first bytes. OpenCV picks a decoder by the file's content and links
/// many (DICOM, JPEG 2000, OpenEXR, ...); some abort the process or exhaust memory on
/// malformed input (fuzz_image found GDCM asserting, and allocating 3.8 GB). Only the
/// formats image sequences come in reach a decoder.
FileKind CheckImageSignature(const std::string& path) {
  if (!std::filesystem::exists(path)) throw InputError(path, "image file does not exist");
  std::ifstream in(path, std::ios::binary);
  unsigned char b[132] = {};
  in.read(reinterpret_cast<char*>(b), sizeof(b));
  const auto n = static_cast<std::size_t>(in.gcount());
  // DICOM's signature is "DICM" after a 128-byte preamble, which may start like any format
  // below; OpenCV then hands the file to GDCM whatever its first bytes (fuzz_image: a "P2"
  // file with DICM at 128 made GDCM allocate 3.8 GB).
  if (n >= 132 && b[128] == 'D' && b[129] == 'I' && b[130] == 'C' && b[131] == 'M') {
    throw InputError(path, "a DICOM file, not an image sequence's frame");
  }
  const auto starts = [&](std::initializer_list<unsigned char> sig) {
    return n >= sig.size() && std::equal(sig.begin(), sig.end(), b);
  };
  if (starts({0x89, 'P', 'N', 'G', 0x0d, 0x0a, 0x1a, 0x0a})) return FileKind::kPng;
  if (starts({0xff, 0xd8, 0xff})) return FileKind::kJpeg;
  const bool bmp = starts({'B', 'M'});
  const bool tiff = starts({'I', 'I', 0x2a, 0x00}) || starts({'M', 'M', 0x00, 0x2a});
  const bool pnm = n >= 2 && b[0] == 'P' && b[1] >= '1' && b[1] <= '6';
  const bool webp = n >= 12 && starts({'R', 'I', 'F', 'F'}) && b[8] == 'W' && b[9] == 'E' &&
                    b[10] == 'B' && b[11] == 'P';
  if (!(bmp || tiff || pnm || webp)) {
    throw InputError(path, "not a PNG, JPEG, BMP, TIFF, PGM/PPM or WebP image");
  }
  return FileKind::kOther;
}

cv::Mat ReadWithOpenCv(const std::string& path, ImageReadMode mode, long long max_pixels) {
  cv::Mat image;
  try {
    image = LoadMediaModule().ReadImage(path, mode == ImageReadMode::kUnchanged);
  } catch (const std::runtime_error& e) {
    throw InputError(path, e.what());
  }
  if (image.empty()) throw InputError(path, "unreadable or corrupt image");
  if (static_cast<long long>(image.cols) * image.rows > max_pixels) {
    throw InputError(path, "image too large");
  }
  return image;
}

/// The native decoder's result, or OpenCV's where the native one leaves the file to it.
cv::Mat Decode(const std::string& path, ImageReadMode mode, long long max_pixels,
               cv::Size* size_only) {
  const FileKind kind = CheckImageSignature(path);
  if (kind == FileKind::kOther) return ReadWithOpenCv(path, mode, max_pixels);
  codecs::DecodeResult decoded = kind == FileKind::kPng
                                     ? codecs::DecodePng(path, mode, max_pixels, size_only)
                                     : codecs::DecodeJpeg(path, mode, max_pixels, size_only);
  switch (decoded.status) {
    case codecs::DecodeStatus::kOk:
      return std::move(decoded.pixels);
    case codecs::DecodeStatus::kNotHandled:
      return ReadWithOpenCv(path, mode, max_pixels);
    case codecs::DecodeStatus::kFailed:
      break;
  }
  throw InputError(path, decoded.message);
}

}  // namespace

cv::Mat ReadImageFile(const std::string& path, ImageReadMode mode, long long max_pixels) {
  return Decode(path, mode, max_pixels, nullptr);
}

cv::Size ProbeImageFile(const std::string& path) {
  cv::Size size;
  const cv::Mat decoded = Decode(path, ImageReadMode::kGrey8, 1LL << 30, &size);
  return decoded.empty() ? size : decoded.size();
}

void WritePngFile(const std::string& path, const cv::Mat& image, int level) {
  std::string message;
  if (!codecs::EncodePng(path, image, std::clamp(level, 0, 9), &message)) {
    throw InputError(path, "cannot write PNG: " + message);
  }
}

}  // namespace parallax
