#include "backend/sim3_ransac.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <random>

#include "core/check.hpp"
#include "core/similarity_fit.hpp"

namespace parallax {

void Sim3RansacOptions::Check() const {
  CheckOption(max_iterations >= 1, "Sim3RansacOptions", "max_iterations", "must be >= 1");
  CheckOption(max_reprojection_chi2 > 0.0, "Sim3RansacOptions", "max_reprojection_chi2",
              "must be > 0");
  CheckOption(min_inliers >= 3, "Sim3RansacOptions", "min_inliers", "must be >= 3");
  CheckOption(confidence > 0.0 && confidence < 1.0, "Sim3RansacOptions", "confidence",
              "must be in (0, 1)");
}

namespace {

bool Reprojects(const PinholeCamera& camera, const Eigen::Vector3d& p, const Eigen::Vector2d& px,
                double sigma, double max_chi2) {
  if (!(p.z() > 1e-9)) return false;
  return (camera.Project(p) - px).squaredNorm() < max_chi2 * sigma * sigma;
}

std::vector<std::uint32_t> Inliers(const std::vector<PointMatch3d>& matches, const Sim3d& S_a_b,
                                   const PinholeCamera& camera, double max_chi2) {
  const Sim3d S_b_a = S_a_b.Inverse();
  std::vector<std::uint32_t> inliers;
  for (std::uint32_t i = 0; i < matches.size(); ++i) {
    if (IsSim3Inlier(matches[i], S_a_b, S_b_a, camera, max_chi2)) inliers.push_back(i);
  }
  return inliers;
}

std::optional<Sim3d> Fit(const std::vector<PointMatch3d>& matches,
                         const std::vector<std::uint32_t>& subset) {
  std::vector<Eigen::Vector3d> x, y;
  for (const std::uint32_t i : subset) {
    x.push_back(matches[i].p_b);
    y.push_back(matches[i].p_a);
  }
  // Three points of a minimal sample must span a triangle of some size, not a sliver.
  return FitSimilarity(x, y, true, 1e-3);
}

}  // namespace

bool IsSim3Inlier(const PointMatch3d& m, const Sim3d& S_a_b, const Sim3d& S_b_a,
                  const PinholeCamera& camera, double max_chi2) {
  return Reprojects(camera, S_a_b * m.p_b, m.px_a, m.sigma_a, max_chi2) &&
         Reprojects(camera, S_b_a * m.p_a, m.px_b, m.sigma_b, max_chi2);
}

Sim3RansacResult EstimateSim3Ransac(const std::vector<PointMatch3d>& matches,
                                    const PinholeCamera& camera, const Sim3RansacOptions& options) {
  options.Check();
  Sim3RansacResult result;
  const auto n = static_cast<std::uint32_t>(matches.size());
  if (n < static_cast<std::uint32_t>(options.min_inliers)) return result;
  std::mt19937_64 random(options.seed);
  std::vector<std::uint32_t> best;
  int needed = options.max_iterations;
  for (int it = 0; it < needed; ++it) {
    ++result.iterations;
    std::uint32_t sample[3];
    for (int k = 0; k < 3; ++k) {
      do {
        sample[k] = static_cast<std::uint32_t>(random() % n);
      } while (std::find(sample, sample + k, sample[k]) != sample + k);
    }
    const auto S = Fit(matches, {sample[0], sample[1], sample[2]});
    if (!S) continue;
    std::vector<std::uint32_t> inliers =
        Inliers(matches, *S, camera, options.max_reprojection_chi2);
    if (inliers.size() <= best.size()) continue;
    best = std::move(inliers);
    // Iterations for the confidence at this inlier share: log(1 - p) / log(1 - w^3).
    const double w = static_cast<double>(best.size()) / n;
    const double all_in = w * w * w;
    if (all_in >= 1.0) break;
    const double k = std::log(1.0 - options.confidence) / std::log(1.0 - all_in);
    needed = std::min(options.max_iterations, static_cast<int>(std::ceil(k)));
  }
  if (best.size() < static_cast<std::size_t>(options.min_inliers)) return result;
  // Refit on all inliers, then take the inliers of the refit (twice: the set may grow).
  for (int round = 0; round < 2; ++round) {
    const auto S = Fit(matches, best);
    if (!S) return result;
    std::vector<std::uint32_t> inliers =
        Inliers(matches, *S, camera, options.max_reprojection_chi2);
    if (inliers.size() < static_cast<std::size_t>(options.min_inliers)) return result;
    result.S_a_b = *S;
    best = std::move(inliers);
  }
  result.found = true;
  result.inliers = std::move(best);
  return result;
}

}  // namespace parallax
