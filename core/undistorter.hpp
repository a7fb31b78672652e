#pragma once
// Remaps images of a distorted camera to an ideal pinhole camera through precomputed maps.

#include <memory>
#include <string>

#include "core/camera.hpp"
#include "core/image.hpp"
#include "core/pinhole_camera.hpp"

namespace parallax {

enum class UndistortMode {
  kCrop,      ///< largest pinhole view whose every pixel sees valid input (no black borders)
  kFull,      ///< pinhole view that contains the whole input image (black where no input)
  kExplicit,  ///< caller-given output intrinsics and size
};

struct UndistorterOptions {
  UndistortMode mode = UndistortMode::kCrop;
  /// Output size in pixels; 0 keeps the input size (kCrop, kFull). Required for kExplicit.
  int output_width = 0;
  int output_height = 0;
  /// Output intrinsics, pixels; used by kExplicit only.
  double fx = 0.0;
  double fy = 0.0;
  double cx = 0.0;
  double cy = 0.0;

  /// Throws std::invalid_argument naming the first bad field.
  void Check() const;
};

/// Maps images of `input` to the pinhole camera OutputCamera() with bilinear interpolation.
/// Output pixels whose source falls outside the input image are 0.
/// The maps are built once in the constructor; Apply is allocation-free given an output
/// image of the right size.
class Undistorter {
 public:
  Undistorter(const Camera& input, const UndistorterOptions& options);
  ~Undistorter();
  Undistorter(Undistorter&&) noexcept;
  Undistorter& operator=(Undistorter&&) noexcept;

  /// The pinhole camera of the output images; it carries a ValidityMask when some output
  /// pixels have no input (kFull, kExplicit views wider than the lens), nothing otherwise.
  const PinholeCamera& OutputCamera() const { return output_; }
  const Camera& InputCamera() const { return input_; }
  /// True when the input is already the output pinhole camera: Apply is then a copy.
  bool IsIdentity() const { return identity_; }

  /// Remaps `image` (must be InputCamera() sized; throws std::invalid_argument otherwise).
  void Apply(const ImageU8& image, ImageU8* output) const;
  ImageU8 Apply(const ImageU8& image) const;

  /// Source position in the input image of output pixel (x, y); (-1, -1) if none.
  Eigen::Vector2f SourceOf(int x, int y) const;

 private:
  struct Maps;
  Camera input_;
  PinholeCamera output_;
  bool identity_ = false;
  std::unique_ptr<Maps> maps_;
};

/// Output pinhole intrinsics chosen by `mode` for `input` (kCrop or kFull), in a
/// width x height image. Exposed for tests and for tools that report the rectified camera.
PinholeCamera ComputeRectifiedCamera(const Camera& input, UndistortMode mode, int width,
                                     int height);

}  // namespace parallax
