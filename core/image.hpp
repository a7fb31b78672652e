#pragma once
// Owning, contiguous, row-major single-channel image.

#include <cstdint>
#include <string>
#include <vector>

#include "core/check.hpp"

namespace parallax {

/// A width x height image of T, row-major without padding (stride == width).
/// Pixel (x, y) is column x, row y; its centre has coordinates (x, y) (docs/conventions.md).
template <typename T>
class Image {
 public:
  Image() = default;
  /// Throws std::invalid_argument for a negative size.
  Image(int width, int height, T fill = T{}) : width_(width), height_(height) {
    CheckArgument(width >= 0 && height >= 0, "Image: size must be non-negative, got " +
                                                 std::to_string(width) + "x" +
                                                 std::to_string(height));
    data_.assign(static_cast<std::size_t>(width) * static_cast<std::size_t>(height), fill);
  }

  int Width() const { return width_; }
  int Height() const { return height_; }
  bool Empty() const { return data_.empty(); }
  std::size_t NumPixels() const { return data_.size(); }

  T* Data() { return data_.data(); }
  const T* Data() const { return data_.data(); }
  T* Row(int y) { return data_.data() + static_cast<std::ptrdiff_t>(y) * width_; }
  const T* Row(int y) const { return data_.data() + static_cast<std::ptrdiff_t>(y) * width_; }
  /// Unchecked access; precondition 0 <= x < Width(), 0 <= y < Height().
  T& operator()(int x, int y) { return Row(y)[x]; }
  const T& operator()(int x, int y) const { return Row(y)[x]; }
  bool Contains(int x, int y) const { return x >= 0 && y >= 0 && x < width_ && y < height_; }

 private:
  int width_ = 0;
  int height_ = 0;
  std::vector<T> data_;
};

using ImageU8 = Image<std::uint8_t>;
using ImageF = Image<float>;

/// Read-only, non-owning view of a row-major image without padding. The viewed memory must
/// outlive the view.
template <typename T>
class ImageView {
 public:
  ImageView() = default;
  ImageView(const T* data, int width, int height) : data_(data), width_(width), height_(height) {}
  /// Views a whole owning image.
  ImageView(const Image<T>& image)  // NOLINT(google-explicit-constructor): views are cheap
      : data_(image.Data()), width_(image.Width()), height_(image.Height()) {}

  int Width() const { return width_; }
  int Height() const { return height_; }
  bool Empty() const { return width_ == 0 || height_ == 0; }
  std::size_t NumPixels() const {
    return static_cast<std::size_t>(width_) * static_cast<std::size_t>(height_);
  }
  const T* Data() const { return data_; }
  const T* Row(int y) const { return data_ + static_cast<std::ptrdiff_t>(y) * width_; }
  /// Unchecked access; precondition 0 <= x < Width(), 0 <= y < Height().
  const T& operator()(int x, int y) const { return Row(y)[x]; }
  bool Contains(int x, int y) const { return x >= 0 && y >= 0 && x < width_ && y < height_; }

 private:
  const T* data_ = nullptr;
  int width_ = 0;
  int height_ = 0;
};

using ImageViewF = ImageView<float>;

/// Bilinear interpolation at (x, y) in pixel-centre coordinates.
/// Precondition: 0 <= x < Width() - 1 and 0 <= y < Height() - 1 (callers bound-check once
/// per point, so the hot path does not check again).
inline float InterpolateBilinear(const ImageViewF& image, float x, float y) {
  const int x0 = static_cast<int>(x);
  const int y0 = static_cast<int>(y);
  const float fx = x - static_cast<float>(x0);
  const float fy = y - static_cast<float>(y0);
  const float* row0 = image.Row(y0) + x0;
  const float* row1 = row0 + image.Width();
  return (1.0f - fy) * ((1.0f - fx) * row0[0] + fx * row0[1]) +
         fy * ((1.0f - fx) * row1[0] + fx * row1[1]);
}

}  // namespace parallax
