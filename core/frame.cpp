#include "core/frame.hpp"

#include <cmath>
#include <string>

#include "core/check.hpp"

namespace parallax {
namespace {

const ImageU8& CheckedImage(const ImageU8& image, const PinholeCamera& camera) {
  CheckArgument(!image.Empty(), "Frame: the image is empty");
  CheckArgument(image.Width() == camera.Width() && image.Height() == camera.Height(),
                "Frame: image is " + std::to_string(image.Width()) + "x" +
                    std::to_string(image.Height()) + " but the camera is " +
                    std::to_string(camera.Width()) + "x" + std::to_string(camera.Height()));
  return image;
}

}  // namespace

Frame::Frame(std::int64_t id, double timestamp, const PinholeCamera& camera, const ImageU8& image,
             const PyramidOptions& pyramid_options)
    : id_(id),
      timestamp_(timestamp),
      validity_(camera.Validity()),
      pyramid_(CheckedImage(image, camera), pyramid_options, validity_.get(),
               LevelZeroGradients::kDeferred) {
  CheckArgument(std::isfinite(timestamp), "Frame: timestamp must be finite");
  cameras_.reserve(static_cast<std::size_t>(pyramid_.NumLevels()));
  for (int level = 0; level < pyramid_.NumLevels(); ++level) {
    cameras_.push_back(camera.AtLevel(level));
  }
}

const PyramidLevel& Frame::LevelZero() const {
  std::call_once(level_zero_once_,
                 [this] { level_zero_ = pyramid_.LevelZeroWithGradients(&level_zero_gradients_); });
  return level_zero_;
}

const ImageF& Frame::MaxGradient() const {
  std::call_once(max_gradient_once_, [this] { max_gradient_ = MaxGradient3x3(Level(0)); });
  return max_gradient_;
}

}  // namespace parallax
