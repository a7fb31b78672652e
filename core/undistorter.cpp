#include "core/undistorter.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "core/check.hpp"
#include "core/validity_mask.hpp"

namespace parallax {

struct Undistorter::Maps {
  cv::Mat map_x;       // CV_32FC1, source x per output pixel (-1 where invalid)
  cv::Mat map_y;       // CV_32FC1
  cv::Mat fixed_xy;    // CV_16SC2, fixed-point form of the same maps used by cv::remap
  cv::Mat fixed_frac;  // CV_16UC1 interpolation table indices
};

namespace {

// An input pixel position is usable when bilinear interpolation stays inside the image.
bool InsideInput(const Camera& camera, const Eigen::Vector2d& uv) {
  return uv.x() >= 0.0 && uv.y() >= 0.0 && uv.x() <= camera.Width() - 1.0 &&
         uv.y() <= camera.Height() - 1.0;
}

bool NormalisedPointIsValid(const Camera& camera, const Eigen::Vector2d& x) {
  const auto uv = camera.Project(Eigen::Vector3d(x.x(), x.y(), 1.0));
  return uv && InsideInput(camera, *uv);
}

struct Rect {
  double x_min, x_max, y_min, y_max;
};

// Bounding box, in normalised coordinates, of the undistorted input-image border.
Rect UndistortedBorderBox(const Camera& camera) {
  Rect box{std::numeric_limits<double>::max(), -std::numeric_limits<double>::max(),
           std::numeric_limits<double>::max(), -std::numeric_limits<double>::max()};
  const int samples = 200;
  const double w = camera.Width() - 1.0;
  const double h = camera.Height() - 1.0;
  bool any = false;
  for (int i = 0; i <= samples; ++i) {
    const double s = static_cast<double>(i) / samples;
    for (const Eigen::Vector2d& uv : {Eigen::Vector2d(s * w, 0.0), Eigen::Vector2d(s * w, h),
                                      Eigen::Vector2d(0.0, s * h), Eigen::Vector2d(w, s * h)}) {
      const auto ray = camera.Unproject(uv);
      if (!ray) continue;
      any = true;
      box.x_min = std::min(box.x_min, ray->x());
      box.x_max = std::max(box.x_max, ray->x());
      box.y_min = std::min(box.y_min, ray->y());
      box.y_max = std::max(box.y_max, ray->y());
    }
  }
  CheckArgument(any, "Undistorter: no border pixel of the input camera can be undistorted (" +
                         camera.ToString() + ")");
  return box;
}

// Shrinks the box edge by edge until every sample on its border maps into the input image
// (the region of valid pixels is star-shaped around the principal point for the supported
// models, so shrinking towards it terminates).
Rect ShrinkToValid(const Camera& camera, Rect box) {
  const int samples = 100;
  for (int iteration = 0; iteration < 2000; ++iteration) {
    bool left = false, right = false, top = false, bottom = false;
    for (int i = 0; i <= samples; ++i) {
      const double s = static_cast<double>(i) / samples;
      const double x = box.x_min + s * (box.x_max - box.x_min);
      const double y = box.y_min + s * (box.y_max - box.y_min);
      left |= !NormalisedPointIsValid(camera, {box.x_min, y});
      right |= !NormalisedPointIsValid(camera, {box.x_max, y});
      top |= !NormalisedPointIsValid(camera, {x, box.y_min});
      bottom |= !NormalisedPointIsValid(camera, {x, box.y_max});
    }
    if (!(left || right || top || bottom)) return box;
    const double step_x = 0.002 * (box.x_max - box.x_min);
    const double step_y = 0.002 * (box.y_max - box.y_min);
    if (left) box.x_min += step_x;
    if (right) box.x_max -= step_x;
    if (top) box.y_min += step_y;
    if (bottom) box.y_max -= step_y;
    CheckArgument(box.x_max > box.x_min && box.y_max > box.y_min,
                  "Undistorter: crop mode found no valid region for " + camera.ToString());
  }
  throw std::invalid_argument("Undistorter: crop mode did not converge for " + camera.ToString());
}

}  // namespace

void UndistorterOptions::Check() const {
  CheckOption(output_width >= 0, "UndistorterOptions", "output_width", "must be >= 0");
  CheckOption(output_height >= 0, "UndistorterOptions", "output_height", "must be >= 0");
  if (mode == UndistortMode::kExplicit) {
    CheckOption(output_width > 0, "UndistorterOptions", "output_width",
                "must be > 0 in explicit mode");
    CheckOption(output_height > 0, "UndistorterOptions", "output_height",
                "must be > 0 in explicit mode");
    CheckOption(std::isfinite(fx) && fx > 0.0, "UndistorterOptions", "fx", "must be > 0");
    CheckOption(std::isfinite(fy) && fy > 0.0, "UndistorterOptions", "fy", "must be > 0");
    CheckOption(std::isfinite(cx), "UndistorterOptions", "cx", "must be finite");
    CheckOption(std::isfinite(cy), "UndistorterOptions", "cy", "must be finite");
  }
}

PinholeCamera ComputeRectifiedCamera(const Camera& input, UndistortMode mode, int width,
                                     int height) {
  CheckArgument(mode != UndistortMode::kExplicit,
                "ComputeRectifiedCamera: explicit mode has no computed camera");
  Rect box = UndistortedBorderBox(input);
  if (mode == UndistortMode::kCrop) box = ShrinkToValid(input, box);
  // Pixel centres 0 and width-1 land on the box edges: u = fx x + cx.
  const double fx = (width - 1.0) / (box.x_max - box.x_min);
  const double fy = (height - 1.0) / (box.y_max - box.y_min);
  return PinholeCamera(width, height, fx, fy, -fx * box.x_min, -fy * box.y_min);
}

namespace {

PinholeCamera ChooseOutput(const Camera& input, const UndistorterOptions& options) {
  options.Check();
  const int w = options.output_width > 0 ? options.output_width : input.Width();
  const int h = options.output_height > 0 ? options.output_height : input.Height();
  if (options.mode == UndistortMode::kExplicit) {
    return PinholeCamera(w, h, options.fx, options.fy, options.cx, options.cy);
  }
  if (input.Model() == CameraModel::kPinhole) {
    // Nothing to undistort: keep the input intrinsics, rescaled if the size changes.
    const PinholeCamera& K = input.Intrinsics();
    const double sx = static_cast<double>(w) / input.Width();
    const double sy = static_cast<double>(h) / input.Height();
    return PinholeCamera(w, h, K.Fx() * sx, K.Fy() * sy, (K.Cx() + 0.5) * sx - 0.5,
                         (K.Cy() + 0.5) * sy - 0.5);
  }
  return ComputeRectifiedCamera(input, options.mode, w, h);
}

}  // namespace

Undistorter::Undistorter(const Camera& input, const UndistorterOptions& options)
    : input_(input), output_(ChooseOutput(input, options)), maps_(std::make_unique<Maps>()) {
  const PinholeCamera& K_in = input.Intrinsics();
  identity_ = input.Model() == CameraModel::kPinhole && output_.Width() == K_in.Width() &&
              output_.Height() == K_in.Height() && output_.Fx() == K_in.Fx() &&
              output_.Fy() == K_in.Fy() && output_.Cx() == K_in.Cx() && output_.Cy() == K_in.Cy();
  maps_->map_x.create(output_.Height(), output_.Width(), CV_32FC1);
  maps_->map_y.create(output_.Height(), output_.Width(), CV_32FC1);
  ImageU8 seen(output_.Width(), output_.Height());
  for (int y = 0; y < output_.Height(); ++y) {
    auto* mx = maps_->map_x.ptr<float>(y);
    auto* my = maps_->map_y.ptr<float>(y);
    for (int x = 0; x < output_.Width(); ++x) {
      const auto uv = input.Project(output_.Unproject(Eigen::Vector2d(x, y)));
      const bool valid = uv && uv->x() > -0.5 && uv->y() > -0.5 && uv->x() < input.Width() - 0.5 &&
                         uv->y() < input.Height() - 0.5;
      mx[x] = valid ? static_cast<float>(uv->x()) : -1.0f;
      my[x] = valid ? static_cast<float>(uv->y()) : -1.0f;
      seen(x, y) = valid ? 1 : 0;
    }
  }
  // Pixels no input reaches (a `full` view's border) must not become texture downstream.
  auto validity = std::make_shared<const ValidityMask>(seen);
  if (!validity->AllValid()) output_ = output_.WithValidity(std::move(validity));
  cv::convertMaps(maps_->map_x, maps_->map_y, maps_->fixed_xy, maps_->fixed_frac, CV_16SC2);
}

Undistorter::~Undistorter() = default;
Undistorter::Undistorter(Undistorter&&) noexcept = default;
Undistorter& Undistorter::operator=(Undistorter&&) noexcept = default;

void Undistorter::Apply(const ImageU8& image, ImageU8* output) const {
  CheckArgument(image.Width() == input_.Width() && image.Height() == input_.Height(),
                "Undistorter::Apply: image is " + std::to_string(image.Width()) + "x" +
                    std::to_string(image.Height()) + " but the camera is " +
                    std::to_string(input_.Width()) + "x" + std::to_string(input_.Height()));
  if (output->Width() != output_.Width() || output->Height() != output_.Height()) {
    *output = ImageU8(output_.Width(), output_.Height());
  }
  if (identity_) {
    std::copy(image.Data(), image.Data() + image.NumPixels(), output->Data());
    return;
  }
  // cv::Mat headers over our buffers: no copies.
  const cv::Mat src(image.Height(), image.Width(), CV_8UC1,
                    const_cast<std::uint8_t*>(image.Data()));
  cv::Mat dst(output->Height(), output->Width(), CV_8UC1, output->Data());
  cv::remap(src, dst, maps_->fixed_xy, maps_->fixed_frac, cv::INTER_LINEAR, cv::BORDER_CONSTANT,
            cv::Scalar(0));
}

ImageU8 Undistorter::Apply(const ImageU8& image) const {
  ImageU8 output(output_.Width(), output_.Height());
  Apply(image, &output);
  return output;
}

Eigen::Vector2f Undistorter::SourceOf(int x, int y) const {
  CheckArgument(x >= 0 && y >= 0 && x < output_.Width() && y < output_.Height(),
                "Undistorter::SourceOf: pixel outside the output image");
  return {maps_->map_x.at<float>(y, x), maps_->map_y.at<float>(y, x)};
}

}  // namespace parallax
