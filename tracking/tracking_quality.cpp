#include "tracking/tracking_quality.hpp"

#include <cmath>

namespace parallax {

void FillPointStatistics(const PointSums& sums, std::size_t total_points, TrackingStats* stats) {
  const auto total = static_cast<double>(total_points);
  stats->points_in_view = sums.in_view;
  stats->points_good = sums.good;
  stats->usage = total > 0 ? sums.in_view / total : 0.0;
  if (sums.in_view <= 0) return;
  stats->residual_rms = std::sqrt(sums.sum_sq_residual / sums.in_view);
  stats->good_ratio = static_cast<double>(sums.good) / sums.in_view;
  stats->mean_gradient_sq = sums.sum_gradient_sq / sums.in_view;
}

TrackingStatus ClassifyConsistency(float min_good_ratio_poor, float min_good_ratio_ok,
                                   TrackingStats* stats) {
  if (stats->good_ratio < min_good_ratio_poor) {
    stats->reason = "most points inconsistent";
    return TrackingStatus::kLost;
  }
  if (stats->good_ratio < min_good_ratio_ok) {
    stats->reason = "many inconsistent points";
    return TrackingStatus::kPoor;
  }
  return TrackingStatus::kOk;
}

}  // namespace parallax
