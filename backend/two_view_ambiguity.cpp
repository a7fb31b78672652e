#include "backend/two_view_ambiguity.hpp"

#include <algorithm>
#include <cmath>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>

#include "core/angles.hpp"

namespace parallax {
namespace {

std::vector<cv::Point2d> ToCv(const std::vector<Eigen::Vector2d>& points) {
  std::vector<cv::Point2d> out;
  out.reserve(points.size());
  for (const Eigen::Vector2d& p : points) out.emplace_back(p.x(), p.y());
  return out;
}

double RotationGapDeg(const SO3d& a, const SO3d& b) {
  return (a.Inverse() * b).Log().norm() * kRadToDeg;
}

/// Angle between two translation directions, sign ignored (the Sampson cost does not see it).
double DirectionGapDeg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  const double angle = AngleBetweenDeg(a, b);
  return std::min(angle, 180.0 - angle);
}

}  // namespace

std::vector<Eigen::Vector2d> Normalised(const PinholeCamera& camera,
                                        const std::vector<Eigen::Vector2d>& pixels) {
  std::vector<Eigen::Vector2d> out;
  out.reserve(pixels.size());
  for (const Eigen::Vector2d& p : pixels) out.push_back(camera.Unproject(p).head<2>());
  return out;
}

std::optional<Eigen::Matrix3d> FitHomography(const PixelCorrespondences& c, double threshold_px) {
  if (c.ref.size() < 4 || c.ref.size() != c.cur.size()) return std::nullopt;
  const cv::Mat H = cv::findHomography(ToCv(c.ref), ToCv(c.cur), cv::RANSAC, threshold_px);
  if (H.rows != 3 || H.cols != 3) return std::nullopt;
  Eigen::Matrix3d out;
  cv::cv2eigen(H, out);
  if (!out.allFinite()) return std::nullopt;
  return out;
}

double HomographyShare(const Eigen::Matrix3d& H, const PixelCorrespondences& c,
                       double threshold_px) {
  if (c.ref.empty()) return 0.0;
  std::size_t explained = 0;
  for (std::size_t i = 0; i < c.ref.size(); ++i) {
    const Eigen::Vector3d x = H * c.ref[i].homogeneous();
    if (std::abs(x.z()) > 1e-12 && (x.hnormalized() - c.cur[i]).norm() < threshold_px) ++explained;
  }
  return static_cast<double>(explained) / static_cast<double>(c.ref.size());
}

std::optional<double> TwinCostRatio(const PinholeCamera& camera, const Eigen::Matrix3d& H,
                                    const PixelCorrespondences& c, const RelativePose& pose,
                                    double min_rotation_deg, double min_direction_deg) {
  cv::Mat H_cv, K_cv;
  cv::eigen2cv(H, H_cv);
  cv::eigen2cv(camera.K(), K_cv);
  std::vector<cv::Mat> rotations, translations, normals;
  const int n = cv::decomposeHomographyMat(H_cv, K_cv, rotations, translations, normals);
  const std::vector<Eigen::Vector2d> ref = Normalised(camera, c.ref);
  const std::vector<Eigen::Vector2d> cur = Normalised(camera, c.cur);
  const double focal = 0.5 * (camera.Fx() + camera.Fy());
  const RelativePoseRefinementOptions polish;
  const double pose_cost = RelativePoseCost(ref, cur, pose, focal, polish.huber_px);
  std::optional<double> best;
  std::vector<SO3d> tried;
  for (std::size_t k = 0; k < static_cast<std::size_t>(std::max(n, 0)); ++k) {
    Eigen::Matrix3d R;
    Eigen::Vector3d t;
    cv::cv2eigen(rotations[k], R);
    cv::cv2eigen(translations[k], t);
    if (t.norm() < 1e-9) continue;  // a pure rotation has no twin to speak of
    const SO3d R_start(R);
    // The decomposition gives each motion twice (normal and translation negated).
    if (std::any_of(tried.begin(), tried.end(),
                    [&](const SO3d& r) { return RotationGapDeg(r, R_start) < 1e-6; })) {
      continue;
    }
    tried.push_back(R_start);
    const RelativePose twin =
        RefineRelativePose(ref, cur, RelativePose{R_start, t.normalized()}, focal, polish);
    if (RotationGapDeg(twin.R_cur_ref, pose.R_cur_ref) <= min_rotation_deg &&
        DirectionGapDeg(twin.t_cur_ref, pose.t_cur_ref) <= min_direction_deg) {
      continue;  // the same motion
    }
    const double ratio =
        RelativePoseCost(ref, cur, twin, focal, polish.huber_px) / std::max(pose_cost, 1e-12);
    best = best ? std::min(*best, ratio) : ratio;
  }
  return best;
}

}  // namespace parallax
