#include "tools/place/vocabulary_training_set.hpp"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

#include "core/check.hpp"
#include "tools/dataset/file_list_reader.hpp"
#include "tools/dataset/opencv_image.hpp"

namespace parallax {

void TrainingSetOptions::Check() const {
  CheckOption(width >= 64 && height >= 64, "TrainingSetOptions", "width",
              "and height must be >= 64");
  for (const double z : zooms) {
    CheckOption(z >= 1.0 && z <= 8.0, "TrainingSetOptions", "zooms", "must be in [1, 8]");
  }
  for (const double g : gammas) {
    CheckOption(g > 0.0 && g <= 10.0, "TrainingSetOptions", "gammas", "must be in (0, 10]");
  }
  CheckOption(blur_sigma >= 0.0, "TrainingSetOptions", "blur_sigma", "must be >= 0");
  orb.Check();
}

namespace {

/// The photograph scaled (area interpolation) to fit width x height times `zoom`.
cv::Mat Fitted(const cv::Mat& photo, int width, int height, double zoom) {
  const double s = zoom * std::min(static_cast<double>(width) / photo.cols,
                                   static_cast<double>(height) / photo.rows);
  cv::Mat out;
  const cv::Size size(std::max(1, static_cast<int>(std::lround(photo.cols * s))),
                      std::max(1, static_cast<int>(std::lround(photo.rows * s))));
  cv::resize(photo, out, size, 0, 0, s < 1.0 ? cv::INTER_AREA : cv::INTER_LINEAR);
  return out;
}

/// Centre and corner crops of at most width x height.
void AddCrops(const cv::Mat& zoomed, int width, int height, std::vector<ImageU8>* views) {
  const int w = std::min(width, zoomed.cols);
  const int h = std::min(height, zoomed.rows);
  const int xs[] = {(zoomed.cols - w) / 2, 0, zoomed.cols - w, 0, zoomed.cols - w};
  const int ys[] = {(zoomed.rows - h) / 2, 0, 0, zoomed.rows - h, zoomed.rows - h};
  for (int k = 0; k < 5; ++k)
    views->push_back(ImageFromGreyMat(zoomed(cv::Rect(xs[k], ys[k], w, h))));
}

}  // namespace

std::vector<ImageU8> AugmentedViews(const ImageU8& photo, const TrainingSetOptions& options) {
  options.Check();
  const cv::Mat source = GreyMatView(photo);
  const cv::Mat base = Fitted(source, options.width, options.height, 1.0);
  std::vector<ImageU8> views{ImageFromGreyMat(base)};
  for (const double zoom : options.zooms) {
    AddCrops(Fitted(source, options.width, options.height, zoom), options.width, options.height,
             &views);
  }
  const cv::Point2f centre(static_cast<float>(base.cols) / 2.0f,
                           static_cast<float>(base.rows) / 2.0f);
  for (const double angle : options.rotations_deg) {
    cv::Mat rotated;
    cv::warpAffine(base, rotated, cv::getRotationMatrix2D(centre, angle, 1.0), base.size(),
                   cv::INTER_LINEAR, cv::BORDER_REFLECT);
    views.push_back(ImageFromGreyMat(rotated));
  }
  for (const double gamma : options.gammas) {
    cv::Mat lut(1, 256, CV_8UC1);
    for (int i = 0; i < 256; ++i) {
      lut.at<std::uint8_t>(i) = cv::saturate_cast<std::uint8_t>(255.0 * std::pow(i / 255.0, gamma));
    }
    cv::Mat adjusted;
    cv::LUT(base, lut, adjusted);
    views.push_back(ImageFromGreyMat(adjusted));
  }
  if (options.blur_sigma > 0.0) {
    cv::Mat blurred;
    cv::GaussianBlur(base, blurred, cv::Size(0, 0), options.blur_sigma);
    views.push_back(ImageFromGreyMat(blurred));
  }
  return views;
}

std::vector<std::vector<OrbDescriptor>> TrainingDescriptors(const std::vector<std::string>& paths,
                                                            const TrainingSetOptions& options) {
  std::vector<std::vector<OrbDescriptor>> images;
  for (const std::string& path : paths) {
    for (const ImageU8& view : AugmentedViews(ReadGreyImage(path), options)) {
      images.push_back(ExtractOrb(view, options.orb).descriptors);
    }
  }
  return images;
}

}  // namespace parallax
