#include "backend/orb_features.hpp"

#include <cmath>
#include <cstring>
#include <opencv2/features2d.hpp>

#include "core/check.hpp"

namespace parallax {

void OrbOptions::Check() const {
  CheckOption(max_features >= 1, "OrbOptions", "max_features", "must be >= 1");
  CheckOption(scale_factor > 1.0f && scale_factor <= 2.0f, "OrbOptions", "scale_factor",
              "must be in (1, 2]");
  CheckOption(levels >= 1 && levels <= 16, "OrbOptions", "levels", "must be in [1, 16]");
  CheckOption(fast_threshold >= 1 && fast_threshold <= 255, "OrbOptions", "fast_threshold",
              "must be in [1, 255]");
  CheckOption(edge_threshold >= 3, "OrbOptions", "edge_threshold", "must be >= 3");
}

std::size_t OrbFeatures::Bytes() const {
  return pixel.capacity() * sizeof(Eigen::Vector2f) + octave.capacity() +
         angle_deg.capacity() * sizeof(float) + descriptors.capacity() * sizeof(OrbDescriptor);
}

OrbFeatures ExtractOrb(const ImageU8& image, const OrbOptions& options) {
  options.Check();
  OrbFeatures features;
  const int margin = 2 * options.edge_threshold + 1;
  if (image.Width() < margin || image.Height() < margin) return features;
  const cv::Mat wrapped(image.Height(), image.Width(), CV_8UC1,
                        const_cast<std::uint8_t*>(image.Data()));
  const cv::Ptr<cv::ORB> orb = cv::ORB::create(
      options.max_features, options.scale_factor, options.levels, options.edge_threshold, 0, 2,
      cv::ORB::HARRIS_SCORE, options.edge_threshold, options.fast_threshold);
  std::vector<cv::KeyPoint> keypoints;
  cv::Mat descriptors;
  orb->detectAndCompute(wrapped, cv::noArray(), keypoints, descriptors);
  if (descriptors.empty()) return features;
  const std::size_t n = keypoints.size();
  features.pixel.reserve(n);
  features.octave.reserve(n);
  features.angle_deg.reserve(n);
  features.descriptors.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    features.pixel.emplace_back(keypoints[i].pt.x, keypoints[i].pt.y);
    features.octave.push_back(static_cast<std::uint8_t>(std::max(0, keypoints[i].octave)));
    features.angle_deg.push_back(keypoints[i].angle);
    std::memcpy(features.descriptors[i].data(), descriptors.ptr(static_cast<int>(i)),
                sizeof(OrbDescriptor));
  }
  return features;
}

double OctaveScale(const OrbOptions& options, int octave) {
  return std::pow(static_cast<double>(options.scale_factor), octave);
}

}  // namespace parallax
