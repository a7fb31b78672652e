#include "backend/two_view_bootstrap.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>
#include <opencv2/features2d.hpp>
#include <opencv2/video/tracking.hpp>

#include "backend/orb_matching.hpp"
#include "backend/relative_pose_refinement.hpp"
#include "backend/two_view_ambiguity.hpp"
#include "core/angles.hpp"
#include "core/check.hpp"

namespace parallax {

struct TwoViewBootstrap::Impl {
  PinholeCamera camera;
  TwoViewBootstrapOptions options;
  cv::Ptr<cv::ORB> orb;
  std::vector<cv::KeyPoint> ref_keypoints;
  std::vector<OrbDescriptor> ref_descriptors;
  ImageU8 ref_image;
};

void TwoViewBootstrapOptions::Check() const {
  CheckOption(max_features >= 50, "TwoViewBootstrapOptions", "max_features", "must be >= 50");
  CheckOption(ratio_test > 0.0f && ratio_test < 1.0f, "TwoViewBootstrapOptions", "ratio_test",
              "must be in (0, 1)");
  CheckOption(min_inliers >= 8, "TwoViewBootstrapOptions", "min_inliers", "must be >= 8");
  CheckOption(min_parallax_deg > 0.0, "TwoViewBootstrapOptions", "min_parallax_deg", "must be > 0");
  CheckOption(min_fallback_parallax_deg >= 0.0, "TwoViewBootstrapOptions",
              "min_fallback_parallax_deg", "must be >= 0");
  CheckOption(parallax_points >= 1, "TwoViewBootstrapOptions", "parallax_points", "must be >= 1");
  CheckOption(max_homography_share > 0.0 && max_homography_share <= 1.0, "TwoViewBootstrapOptions",
              "max_homography_share", "must be in (0, 1]");
  CheckOption(min_twin_cost_ratio >= 0.0, "TwoViewBootstrapOptions", "min_twin_cost_ratio",
              "must be >= 0");
  CheckOption(max_offset_sigma >= 0.0, "TwoViewBootstrapOptions", "max_offset_sigma",
              "must be >= 0");
}

TwoViewBootstrap::TwoViewBootstrap(const PinholeCamera& camera,
                                   const TwoViewBootstrapOptions& options)
    : impl_(std::make_unique<Impl>(
          Impl{camera, options, cv::ORB::create(options.max_features), {}, {}, {}})) {
  options.Check();
}
TwoViewBootstrap::~TwoViewBootstrap() = default;
TwoViewBootstrap::TwoViewBootstrap(TwoViewBootstrap&&) noexcept = default;
TwoViewBootstrap& TwoViewBootstrap::operator=(TwoViewBootstrap&&) noexcept = default;

namespace {
cv::Mat Wrap(const ImageU8& image) {
  return cv::Mat(image.Height(), image.Width(), CV_8UC1, const_cast<std::uint8_t*>(image.Data()));
}

/// Mean grey value of the 5x5 patch around `p` (clamped to the image).
double PatchMean(const ImageU8& image, const cv::Point2d& p) {
  const int cx = std::clamp(static_cast<int>(std::lround(p.x)), 2, image.Width() - 3);
  const int cy = std::clamp(static_cast<int>(std::lround(p.y)), 2, image.Height() - 3);
  double sum = 0.0;
  for (int y = cy - 2; y <= cy + 2; ++y) {
    for (int x = cx - 2; x <= cx + 2; ++x) sum += image(x, y);
  }
  return sum / 25.0;
}

/// Fits I_b ~ gain * I_a + offset by matching the means and standard deviations of the patch
/// means (a moment fit is symmetric in the noise of both views, unlike least squares on one).
void FitBrightness(const std::vector<double>& a, const std::vector<double>& b, TwoViewPair* pair) {
  const auto n = static_cast<double>(a.size());
  double mean_a = 0.0, mean_b = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    mean_a += a[i];
    mean_b += b[i];
  }
  mean_a /= n;
  mean_b /= n;
  double var_a = 0.0, var_b = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    var_a += (a[i] - mean_a) * (a[i] - mean_a);
    var_b += (b[i] - mean_b) * (b[i] - mean_b);
  }
  if (var_a < 1e-6 || var_b < 1e-6) return;  // flat patches: keep gain 1, offset 0
  const double gain = std::clamp(std::sqrt(var_b / var_a), 0.25, 4.0);
  pair->gain = static_cast<float>(gain);
  pair->offset = static_cast<float>(mean_b - gain * mean_a);
}

/// OpenCV's descriptor rows (32 bytes each) as OrbDescriptors.
std::vector<OrbDescriptor> ToDescriptors(const cv::Mat& rows) {
  std::vector<OrbDescriptor> descriptors(static_cast<std::size_t>(rows.rows));
  for (int i = 0; i < rows.rows; ++i)
    std::memcpy(descriptors[static_cast<std::size_t>(i)].data(), rows.ptr(i),
                sizeof(OrbDescriptor));
  return descriptors;
}
}  // namespace

void TwoViewBootstrap::SetReference(const ImageU8& image) {
  impl_->ref_keypoints.clear();
  cv::Mat descriptors;
  impl_->orb->detectAndCompute(Wrap(image), cv::noArray(), impl_->ref_keypoints, descriptors);
  impl_->ref_descriptors = ToDescriptors(descriptors);
  impl_->ref_image = image;
}

namespace {

struct Matches {
  std::vector<cv::Point2d> ref, cur;
};

/// Lowe-ratio-filtered ORB matches from the reference to the frame.
Matches MatchFeatures(const std::vector<cv::KeyPoint>& ref_keypoints,
                      const std::vector<OrbDescriptor>& ref_descriptors,
                      const std::vector<cv::KeyPoint>& keypoints, const cv::Mat& descriptors,
                      float ratio_test) {
  const std::vector<NearestTwo> nearest =
      NearestTwoByHamming(ref_descriptors, ToDescriptors(descriptors));
  Matches matches;
  for (std::size_t i = 0; i < nearest.size(); ++i) {
    const NearestTwo& m = nearest[i];
    // In float, as the ratio was compared when it was chosen (with OpenCV's DMatch).
    if (m.second >= 0 && static_cast<float>(m.nearest_distance) <
                             ratio_test * static_cast<float>(m.second_distance)) {
      matches.ref.push_back(ref_keypoints[i].pt);
      matches.cur.push_back(keypoints[static_cast<std::size_t>(m.nearest)].pt);
    }
  }
  return matches;
}

/// Triangulated inliers: depth in the reference and triangulation angle (degrees).
struct Triangulation {
  std::vector<double> depths, angles_deg;
  std::vector<std::size_t> match_index;
};

Triangulation CollectInliers(const cv::Mat& triangulated, const cv::Mat& inlier_mask,
                             const Eigen::Vector3d& centre_cur_in_ref) {
  Triangulation out;
  for (int i = 0; i < triangulated.cols; ++i) {
    if (!inlier_mask.at<std::uint8_t>(i)) continue;
    const double w = triangulated.at<double>(3, i);
    if (std::abs(w) < 1e-12) continue;
    const Eigen::Vector3d X(triangulated.at<double>(0, i) / w, triangulated.at<double>(1, i) / w,
                            triangulated.at<double>(2, i) / w);
    if (X.z() <= 0.0) continue;
    out.angles_deg.push_back(AngleBetweenDeg(X, X - centre_cur_in_ref));
    out.depths.push_back(X.z());
    out.match_index.push_back(static_cast<std::size_t>(i));
  }
  return out;
}

/// The k-th largest value (k >= 1, clamped to the size). Precondition: values not empty.
double KthLargest(std::vector<double> values, int k) {
  const auto n = static_cast<std::ptrdiff_t>(values.size());
  const std::ptrdiff_t index = std::max<std::ptrdiff_t>(0, n - std::min<std::ptrdiff_t>(k, n));
  std::nth_element(values.begin(), values.begin() + index, values.end());
  return values[static_cast<std::size_t>(index)];
}

/// ORB positions are only as precise as the pyramid level a corner was found on (1.2^level
/// pixels); a Lucas-Kanade step from each reference point, started at its ORB match, aligns
/// the patches to a fraction of a pixel. Matches the step loses or moves by more than 2 pixels
/// (not the same patch) are dropped.
void RefineMatchesByKlt(const ImageU8& ref, const ImageU8& cur, Matches* matches) {
  std::vector<cv::Point2f> ref_points, cur_points;
  for (std::size_t i = 0; i < matches->ref.size(); ++i) {
    ref_points.emplace_back(matches->ref[i]);
    cur_points.emplace_back(matches->cur[i]);
  }
  const std::vector<cv::Point2f> orb_points = cur_points;
  std::vector<std::uint8_t> status;
  std::vector<float> error;
  cv::calcOpticalFlowPyrLK(
      Wrap(ref), Wrap(cur), ref_points, cur_points, status, error, cv::Size(11, 11), 1,
      cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 20, 0.01),
      cv::OPTFLOW_USE_INITIAL_FLOW);
  Matches kept;
  for (std::size_t i = 0; i < ref_points.size(); ++i) {
    const cv::Point2f shift = cur_points[i] - orb_points[i];
    if (!status[i] || shift.dot(shift) > 4.0f) continue;
    kept.ref.push_back(matches->ref[i]);
    kept.cur.emplace_back(cur_points[i]);
  }
  *matches = std::move(kept);
}

PixelCorrespondences Inlying(const Matches& matches, const std::vector<std::size_t>& inliers) {
  PixelCorrespondences c;
  for (const std::size_t i : inliers) {
    c.ref.emplace_back(matches.ref[i].x, matches.ref[i].y);
    c.cur.emplace_back(matches.cur[i].x, matches.cur[i].y);
  }
  return c;
}

/// The inliers in normalised image coordinates, for the polish and its covariance.
struct NormalisedInliers {
  std::vector<Eigen::Vector2d> ref, cur;
  double focal_px = 0.0;
};

NormalisedInliers Normalise(const PinholeCamera& camera, const PixelCorrespondences& inliers) {
  return {Normalised(camera, inliers.ref), Normalised(camera, inliers.cur),
          0.5 * (camera.Fx() + camera.Fy())};
}

/// The RANSAC model is a 5-point solution; every cheirality-checked inlier refines it.
RelativePose PolishOnInliers(const NormalisedInliers& inliers, const RelativePose& pose) {
  return RefineRelativePose(inliers.ref, inliers.cur, pose, inliers.focal_px);
}

/// Standard deviation of the polished rotation along its least determined axis, radians.
double RotationSigma(const NormalisedInliers& inliers, const RelativePose& pose) {
  if (inliers.ref.size() < 6) return std::numeric_limits<double>::infinity();
  const Eigen::Matrix3d covariance =
      RelativePoseCovariance(inliers.ref, inliers.cur, pose, inliers.focal_px,
                             RelativePoseRefinementOptions{}.huber_px)
          .topLeftCorner<3, 3>();
  if (!covariance.allFinite()) return std::numeric_limits<double>::infinity();
  return std::sqrt(std::max(
      0.0, Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(covariance).eigenvalues().maxCoeff()));
}

/// False when the pair's inliers do not determine its motion (docs/math/two_view.md,
/// "Ambiguous pairs"): a homography explains too many of them, or another motion explains
/// them almost as well.
bool Determined(const PinholeCamera& camera, const TwoViewBootstrapOptions& options,
                const PixelCorrespondences& inliers, const RelativePose& pose) {
  if (options.max_homography_share >= 1.0 && options.min_twin_cost_ratio <= 0.0) return true;
  const auto H = FitHomography(inliers, options.ransac_threshold_px);
  if (!H) return true;  // no homography explains them
  if (HomographyShare(*H, inliers, options.ransac_threshold_px) > options.max_homography_share) {
    return false;
  }
  if (options.min_twin_cost_ratio <= 0.0) return true;
  const std::optional<double> twin = TwinCostRatio(camera, *H, inliers, pose);
  return !twin || *twin >= options.min_twin_cost_ratio;
}

}  // namespace

std::optional<TwoViewPair> TwoViewBootstrap::TryFrame(const ImageU8& image,
                                                      std::optional<TwoViewPair>* fallback) {
  const TwoViewBootstrapOptions& options = impl_->options;
  if (impl_->ref_keypoints.size() < 50) return std::nullopt;
  std::vector<cv::KeyPoint> keypoints;
  cv::Mat descriptors;
  impl_->orb->detectAndCompute(Wrap(image), cv::noArray(), keypoints, descriptors);
  if (keypoints.size() < 50) return std::nullopt;
  Matches matches = MatchFeatures(impl_->ref_keypoints, impl_->ref_descriptors, keypoints,
                                  descriptors, options.ratio_test);
  if (static_cast<int>(matches.ref.size()) < options.min_inliers) return std::nullopt;
  RefineMatchesByKlt(impl_->ref_image, image, &matches);
  if (static_cast<int>(matches.ref.size()) < options.min_inliers) return std::nullopt;
  cv::Mat K, inlier_mask, R, t, triangulated;
  cv::eigen2cv(impl_->camera.K(), K);
  const cv::Mat E = cv::findEssentialMat(matches.ref, matches.cur, K, cv::RANSAC, 0.999,
                                         options.ransac_threshold_px, inlier_mask);
  if (E.rows != 3 || E.cols != 3) return std::nullopt;  // degenerate or several solutions
  const int good =
      cv::recoverPose(E, matches.ref, matches.cur, K, R, t, 50.0, inlier_mask, triangulated);
  if (good < options.min_inliers) return std::nullopt;
  Eigen::Matrix3d R_e;
  Eigen::Vector3d t_e;
  cv::cv2eigen(R, R_e);
  cv::cv2eigen(t, t_e);
  Triangulation tri = CollectInliers(triangulated, inlier_mask, -R_e.transpose() * t_e);
  if (static_cast<int>(tri.depths.size()) < options.min_inliers) return std::nullopt;
  TwoViewPair pair;
  pair.parallax_deg = KthLargest(tri.angles_deg, options.parallax_points);
  const bool enough_parallax = pair.parallax_deg >= options.min_parallax_deg;
  const bool offer_fallback = fallback != nullptr && options.min_fallback_parallax_deg > 0.0 &&
                              pair.parallax_deg >= options.min_fallback_parallax_deg;
  if (!enough_parallax && !offer_fallback) return std::nullopt;
  const PixelCorrespondences inliers = Inlying(matches, tri.match_index);
  const NormalisedInliers normalised = Normalise(impl_->camera, inliers);
  const RelativePose refined = PolishOnInliers(normalised, {SO3d(R_e), t_e.normalized()});
  // |t| = 1 in recoverPose's units; scale so the median reference depth becomes 1.
  const double median_depth = KthLargest(tri.depths, static_cast<int>(tri.depths.size() / 2) + 1);
  const double rotation_sigma = RotationSigma(normalised, refined);
  pair.rotation_sigma_deg = rotation_sigma * kRadToDeg;
  pair.inverse_depth_offset_sigma = rotation_sigma * median_depth;
  if (options.max_offset_sigma > 0.0 &&
      !(pair.inverse_depth_offset_sigma <= options.max_offset_sigma)) {
    return std::nullopt;
  }
  if (!Determined(impl_->camera, options, inliers, refined)) {
    return std::nullopt;
  }
  pair.T_frame_ref = SE3d(refined.R_cur_ref, refined.t_cur_ref / median_depth);
  pair.inliers = static_cast<int>(tri.depths.size());
  std::vector<double> ref_means, cur_means;
  for (const std::size_t i : tri.match_index) {
    ref_means.push_back(PatchMean(impl_->ref_image, matches.ref[i]));
    cur_means.push_back(PatchMean(image, matches.cur[i]));
  }
  FitBrightness(ref_means, cur_means, &pair);
  if (!enough_parallax) {
    *fallback = pair;
    return std::nullopt;
  }
  return pair;
}

}  // namespace parallax
