#include "backend/relocalizer.hpp"

#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>

#include "backend/keypoint_depth.hpp"
#include "core/check.hpp"

namespace parallax {

void RelocalizationOptions::Check() const {
  CheckOption(max_candidates >= 1, "RelocalizationOptions", "max_candidates", "must be >= 1");
  CheckOption(min_score >= 0.0 && min_score <= 1.0, "RelocalizationOptions", "min_score",
              "must be in [0, 1]");
  CheckOption(min_inliers >= 6, "RelocalizationOptions", "min_inliers", "must be >= 6");
  CheckOption(min_matches >= min_inliers, "RelocalizationOptions", "min_matches",
              "must be >= min_inliers");
  CheckOption(max_reprojection_px > 0.0, "RelocalizationOptions", "max_reprojection_px",
              "must be > 0");
  CheckOption(ransac_iterations >= 1, "RelocalizationOptions", "ransac_iterations", "must be >= 1");
  CheckOption(max_relative_depth_std > 0.0, "RelocalizationOptions", "max_relative_depth_std",
              "must be > 0");
}

Relocalizer::Relocalizer(const RelocalizationOptions& options, const PinholeCamera& camera)
    : options_(options), camera_(camera) {
  options_.Check();
}

std::vector<RelocalizationGuess> Relocalizer::Propose(const KeyframeGraph& graph,
                                                      const PlaceRecognizer& recognizer,
                                                      const PlaceEntry& frame) const {
  std::vector<RelocalizationGuess> guesses;
  const auto candidates = recognizer.Database().Query(
      frame.bow, [&](std::int64_t id) { return !graph.Contains(id); },
      static_cast<std::size_t>(options_.max_candidates), options_.min_score);
  const cv::Matx33d K(camera_.Fx(), 0.0, camera_.Cx(), 0.0, camera_.Fy(), camera_.Cy(), 0.0, 0.0,
                      1.0);
  for (const DatabaseMatch& candidate : candidates) {
    const PlaceEntry& keyframe = recognizer.Entry(candidate.keyframe_id);
    const KeypointDepth depth(graph.Get(candidate.keyframe_id).depth, camera_,
                              options_.max_relative_depth_std);
    std::vector<cv::Point3f> points;
    std::vector<cv::Point2f> pixels;
    for (const auto& [i, j] : MatchByNodes(keyframe, frame, recognizer.Options())) {
      const auto p = depth.Point(keyframe.features.pixel[i]);
      if (!p) continue;
      points.emplace_back(static_cast<float>(p->x()), static_cast<float>(p->y()),
                          static_cast<float>(p->z()));
      pixels.emplace_back(frame.features.pixel[j].x(), frame.features.pixel[j].y());
    }
    if (static_cast<int>(points.size()) < options_.min_matches) continue;
    cv::Vec3d rvec, tvec;
    std::vector<int> inliers;
    // OpenCV's RANSAC draws from its own fixed-seed generator: deterministic.
    const bool found = cv::solvePnPRansac(
        points, pixels, K, cv::noArray(), rvec, tvec, false, options_.ransac_iterations,
        static_cast<float>(options_.max_reprojection_px), 0.999, inliers, cv::SOLVEPNP_EPNP);
    if (!found || static_cast<int>(inliers.size()) < options_.min_inliers) continue;
    const Eigen::Vector3d omega(rvec[0], rvec[1], rvec[2]);
    const SE3d T_frame_kf(SO3d::Exp(omega), Eigen::Vector3d(tvec[0], tvec[1], tvec[2]));
    if (!T_frame_kf.Translation().allFinite()) continue;
    guesses.push_back({candidate.keyframe_id, T_frame_kf.Inverse(),
                       static_cast<int>(inliers.size()), candidate.score});
  }
  return guesses;
}

}  // namespace parallax
