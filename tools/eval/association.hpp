#pragma once
// Timestamp association between an estimated and a ground-truth trajectory.

#include <vector>

#include "tools/dataset/trajectory.hpp"

namespace parallax {

/// One associated pair: indices into the estimate and the ground truth.
struct AssociatedPair {
  std::size_t estimate_index;
  std::size_t groundtruth_index;
};

/// One-to-one greedy association as in the TUM benchmark's associate.py: every pair with
/// |t_est - t_gt| < max_dt is a candidate; candidates are accepted by increasing |dt| while
/// neither pose is taken. Both trajectories must be sorted by time. The result is sorted by
/// estimate time.
std::vector<AssociatedPair> AssociateByTimestamp(const Trajectory& estimate,
                                                 const Trajectory& groundtruth, double max_dt);

}  // namespace parallax
