#pragma once
// Image files as the dataset readers, the renderer and the exporters use them. PNG and JPEG
// are decoded with libpng and libjpeg directly; other formats (BMP, TIFF, PGM/PPM, WebP) go
// to the optional media module (tools/dataset/media_module.hpp), which links OpenCV's
// codecs. Why: OpenCV's imgcodecs and videoio pull about 220 shared libraries into every
// process that links them, 0.2 s of start-up (docs/architecture.md, "Image files").

#include <opencv2/core.hpp>
#include <string>

namespace parallax {

/// How a file's pixels are returned.
enum class ImageReadMode {
  kGrey8,      ///< 8-bit single channel, as cv::imread(path, IMREAD_GRAYSCALE) gives it
  kUnchanged,  ///< the file's depth and channels (BGR order), as IMREAD_UNCHANGED gives it
};

/// The pixels of `path`. Throws InputError naming the file when it is missing, not an image
/// format the readers accept, corrupt, or larger than `max_pixels`.
cv::Mat ReadImageFile(const std::string& path, ImageReadMode mode,
                      long long max_pixels = 1LL << 30);

/// Width and height of `path` from its header (PNG, JPEG) or a full decode (other formats).
cv::Size ProbeImageFile(const std::string& path);

/// Writes an 8-bit or 16-bit, one- or three-channel (BGR) matrix as PNG; zlib `level` 0-9.
/// Throws InputError naming the file when it cannot be written.
void WritePngFile(const std::string& path, const cv::Mat& image, int level = 1);

}  // namespace parallax
