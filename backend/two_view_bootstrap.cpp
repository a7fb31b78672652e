#include "backend/two_view_bootstrap.hpp"

#include <algorithm>
#include <cmath>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>
#include <opencv2/features2d.hpp>

#include "core/check.hpp"

namespace parallax {

struct TwoViewBootstrap::Impl {
  PinholeCamera camera;
  TwoViewBootstrapOptions options;
  cv::Ptr<cv::ORB> orb;
  std::vector<cv::KeyPoint> ref_keypoints;
  cv::Mat ref_descriptors;
};

void TwoViewBootstrapOptions::Check() const {
  CheckOption(max_features >= 50, "TwoViewBootstrapOptions", "max_features", "must be >= 50");
  CheckOption(ratio_test > 0.0f && ratio_test < 1.0f, "TwoViewBootstrapOptions", "ratio_test",
              "must be in (0, 1)");
  CheckOption(min_inliers >= 8, "TwoViewBootstrapOptions", "min_inliers", "must be >= 8");
  CheckOption(min_parallax_deg > 0.0, "TwoViewBootstrapOptions", "min_parallax_deg", "must be > 0");
}

TwoViewBootstrap::TwoViewBootstrap(const PinholeCamera& camera,
                                   const TwoViewBootstrapOptions& options)
    : impl_(std::make_unique<Impl>(
          Impl{camera, options, cv::ORB::create(options.max_features), {}, {}})) {
  options.Check();
}
TwoViewBootstrap::~TwoViewBootstrap() = default;
TwoViewBootstrap::TwoViewBootstrap(TwoViewBootstrap&&) noexcept = default;
TwoViewBootstrap& TwoViewBootstrap::operator=(TwoViewBootstrap&&) noexcept = default;

namespace {
cv::Mat Wrap(const ImageU8& image) {
  return cv::Mat(image.Height(), image.Width(), CV_8UC1, const_cast<std::uint8_t*>(image.Data()));
}
}  // namespace

void TwoViewBootstrap::SetReference(const ImageU8& image) {
  impl_->ref_keypoints.clear();
  impl_->orb->detectAndCompute(Wrap(image), cv::noArray(), impl_->ref_keypoints,
                               impl_->ref_descriptors);
}

std::optional<SE3d> TwoViewBootstrap::TryFrame(const ImageU8& image) {
  if (impl_->ref_keypoints.size() < 50) return std::nullopt;
  std::vector<cv::KeyPoint> keypoints;
  cv::Mat descriptors;
  impl_->orb->detectAndCompute(Wrap(image), cv::noArray(), keypoints, descriptors);
  if (keypoints.size() < 50) return std::nullopt;
  cv::BFMatcher matcher(cv::NORM_HAMMING);
  std::vector<std::vector<cv::DMatch>> knn;
  matcher.knnMatch(impl_->ref_descriptors, descriptors, knn, 2);
  std::vector<cv::Point2d> ref_points, cur_points;
  for (const auto& m : knn) {
    if (m.size() == 2 && m[0].distance < impl_->options.ratio_test * m[1].distance) {
      ref_points.push_back(impl_->ref_keypoints[static_cast<std::size_t>(m[0].queryIdx)].pt);
      cur_points.push_back(keypoints[static_cast<std::size_t>(m[0].trainIdx)].pt);
    }
  }
  if (static_cast<int>(ref_points.size()) < impl_->options.min_inliers) return std::nullopt;
  cv::Mat K;
  cv::eigen2cv(impl_->camera.K(), K);
  cv::Mat inlier_mask;
  const cv::Mat E = cv::findEssentialMat(ref_points, cur_points, K, cv::RANSAC, 0.999,
                                         impl_->options.ransac_threshold_px, inlier_mask);
  if (E.rows != 3 || E.cols != 3) return std::nullopt;
  cv::Mat R, t, triangulated;
  const int good =
      cv::recoverPose(E, ref_points, cur_points, K, R, t, 50.0, inlier_mask, triangulated);
  if (good < impl_->options.min_inliers) return std::nullopt;
  Eigen::Matrix3d R_e;
  Eigen::Vector3d t_e;
  cv::cv2eigen(R, R_e);
  cv::cv2eigen(t, t_e);
  // Triangulation angles and depths in the reference of the inliers.
  std::vector<double> angles, depths;
  const Eigen::Vector3d centre_cur_in_ref = -R_e.transpose() * t_e;
  for (int i = 0; i < triangulated.cols; ++i) {
    if (!inlier_mask.at<std::uint8_t>(i)) continue;
    const double w = triangulated.at<double>(3, i);
    if (std::abs(w) < 1e-12) continue;
    const Eigen::Vector3d X(triangulated.at<double>(0, i) / w, triangulated.at<double>(1, i) / w,
                            triangulated.at<double>(2, i) / w);
    if (X.z() <= 0.0) continue;
    const Eigen::Vector3d a = X.normalized(), b = (X - centre_cur_in_ref).normalized();
    angles.push_back(std::acos(std::clamp(a.dot(b), -1.0, 1.0)) * 180.0 / 3.14159265358979);
    depths.push_back(X.z());
  }
  if (static_cast<int>(depths.size()) < impl_->options.min_inliers) return std::nullopt;
  std::nth_element(angles.begin(), angles.begin() + static_cast<std::ptrdiff_t>(angles.size() / 2),
                   angles.end());
  if (angles[angles.size() / 2] < impl_->options.min_parallax_deg) return std::nullopt;
  std::nth_element(depths.begin(), depths.begin() + static_cast<std::ptrdiff_t>(depths.size() / 2),
                   depths.end());
  const double median_depth = depths[depths.size() / 2];
  // |t| = 1 in recoverPose's units; scale so the median reference depth becomes 1.
  return SE3d(SO3d(R_e), t_e / median_depth);
}

}  // namespace parallax
