#pragma once
// Conversions between the engine's 8-bit images and OpenCV matrices (tools only; the engine
// layers keep OpenCV out of their interfaces).

#include <algorithm>
#include <cstdint>
#include <opencv2/core.hpp>

#include "core/image.hpp"

namespace parallax {

/// A cv::Mat header over the image's pixels: no copy, valid while `image` lives and is not
/// resized; read-only use (OpenCV's constructor takes a non-const pointer).
inline cv::Mat GreyMatView(const ImageU8& image) {
  return cv::Mat(image.Height(), image.Width(), CV_8UC1, const_cast<std::uint8_t*>(image.Data()));
}

/// A copy of an 8-bit single-channel matrix (any row stride).
inline ImageU8 ImageFromGreyMat(const cv::Mat& grey) {
  ImageU8 image(grey.cols, grey.rows);
  for (int y = 0; y < grey.rows; ++y) {
    std::copy(grey.ptr<std::uint8_t>(y), grey.ptr<std::uint8_t>(y) + grey.cols, image.Row(y));
  }
  return image;
}

}  // namespace parallax
