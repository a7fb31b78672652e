#pragma once
// Float intensity pyramid with per-level gradients, and semi-dense pixel selection.

#include <memory>
#include <vector>

#include "core/buffer_pool.hpp"
#include "core/image.hpp"
#include "core/validity_mask.hpp"

namespace parallax {

struct PyramidOptions {
  /// Upper bound on the number of levels (level 0 is the input resolution).
  int max_levels = 5;
  /// A coarser level is built only while both its width and height stay >= this (pixels).
  int min_level_size = 16;

  /// Throws std::invalid_argument naming the first bad field.
  void Check() const;
};

/// One pyramid level: views of the level's planes, all of the level's size. Intensities are
/// in the input's 0..255 units. Gradients are central differences, (I(x+1) - I(x-1)) / 2, in
/// intensity units per pixel of this level; they are 0 on the one-pixel image border where
/// the stencil would leave the image.
struct PyramidLevel {
  ImageViewF intensity;
  ImageViewF dx;
  ImageViewF dy;
  /// ValidityMask::Level of this level (row-major, this level's size): 0 where the pixel or
  /// its stencils see no input, and dx, dy are 0 there. nullptr: all pixels valid.
  const std::uint8_t* valid = nullptr;

  int Width() const { return intensity.Width(); }
  int Height() const { return intensity.Height(); }
  /// dx^2 + dy^2 at a pixel. Computed where it is asked for rather than stored: few pixels
  /// need it, and a fourth plane was a quarter of every frame's pyramid.
  float GradSq(int x, int y) const {
    const float gx = dx(x, y), gy = dy(x, y);
    return gx * gx + gy * gy;
  }
};

/// Whether an ImagePyramid computes level 0's gradients when it is built.
enum class LevelZeroGradients {
  kComputed,
  kDeferred,  ///< level 0 has intensity only (dx, dy empty): LevelZeroWithGradients
};

/// Intensity pyramid of an 8-bit grey image. Level l+1 has size floor(w_l / 2) x
/// floor(h_l / 2); each of its pixels is the mean of a 2x2 block of level l. With an odd size
/// the last column (row) of level l has no parent and is dropped, so pixel centres keep the
/// relation u_l = (u_0 + 0.5) / 2^l - 0.5 (docs/conventions.md, "Pyramid").
///
/// All planes of all levels live in one allocation (one page-fault burst per frame rather
/// than one per plane, and better locality). Move-only: levels view the owned buffer.
class ImagePyramid {
 public:
  /// Throws std::invalid_argument for an empty image, invalid options or a `validity` whose
  /// level 0 is not the image's size. `validity` (may be null) must outlive the pyramid.
  explicit ImagePyramid(const ImageView<std::uint8_t>& image, const PyramidOptions& options = {},
                        const ValidityMask* validity = nullptr,
                        LevelZeroGradients level_zero = LevelZeroGradients::kComputed);
  ImagePyramid(const ImagePyramid&) = delete;
  ImagePyramid& operator=(const ImagePyramid&) = delete;
  ImagePyramid(ImagePyramid&&) noexcept = default;
  ImagePyramid& operator=(ImagePyramid&&) noexcept = default;
  ~ImagePyramid() = default;

  int NumLevels() const { return static_cast<int>(levels_.size()); }
  /// Precondition: 0 <= level < NumLevels().
  const PyramidLevel& Level(int level) const { return levels_[static_cast<std::size_t>(level)]; }
  /// Level 0 with its gradients, computed into `storage` (taken from the shared pool), as
  /// the constructor computes them: for a pyramid built with LevelZeroGradients::kDeferred.
  PyramidLevel LevelZeroWithGradients(FloatBufferPool::Buffer* storage) const;

 private:
  FloatBufferPool::Buffer buffer_;  ///< from FloatBufferPool::Shared()
  std::vector<PyramidLevel> levels_;
};

/// Number of levels ImagePyramid builds for a width x height image.
int NumPyramidLevels(int width, int height, const PyramidOptions& options);

/// Per pixel, the largest gradient magnitude |grad I| in its 3x3 neighbourhood (clamped at
/// the image border), 0 where the level's validity mask excludes the pixel. LSD-SLAM selects
/// semi-dense pixels on this, so that thin edges contribute the pixels on both sides.
ImageF MaxGradient3x3(const PyramidLevel& level);

/// Row-major indices (y * width + x) of the pixels whose 3x3 max gradient is >= min_gradient,
/// at least `border` pixels away from the image edge. Sorted ascending.
std::vector<int> SelectSemiDensePixels(const PyramidLevel& level, float min_gradient,
                                       int border = 2);

}  // namespace parallax
