#pragma once
// Tracking statistics and the consistency part of the status decision, shared by the SE(3)
// and Sim(3) trackers.

#include <cstddef>
#include <string>

#include "tracking/tracking_result.hpp"

namespace parallax {

/// Sums over the points in view at the finest level.
struct PointSums {
  int in_view = 0;
  int good = 0;
  double sum_sq_residual = 0.0;
  double sum_gradient_sq = 0.0;
};

/// Fills points_in_view, usage (in view / total), residual_rms, good_ratio, mean_gradient_sq.
void FillPointStatistics(const PointSums& sums, std::size_t total_points, TrackingStats* stats);

/// Lost below `min_good_ratio_poor`, poor below `min_good_ratio_ok`, else ok; sets the reason.
TrackingStatus ClassifyConsistency(float min_good_ratio_poor, float min_good_ratio_ok,
                                   TrackingStats* stats);

}  // namespace parallax
