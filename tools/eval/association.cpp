#include "tools/eval/association.hpp"

#include <algorithm>
#include <cmath>

namespace parallax {

std::vector<AssociatedPair> AssociateByTimestamp(const Trajectory& estimate,
                                                 const Trajectory& groundtruth, double max_dt) {
  struct Candidate {
    double dt;
    std::size_t e;
    std::size_t g;
  };
  std::vector<Candidate> candidates;
  for (std::size_t e = 0; e < estimate.size(); ++e) {
    const double t = estimate[e].timestamp;
    auto it = std::lower_bound(groundtruth.begin(), groundtruth.end(), t - max_dt,
                               [](const StampedPose& p, double v) { return p.timestamp < v; });
    for (; it != groundtruth.end() && it->timestamp < t + max_dt; ++it) {
      const double dt = std::abs(it->timestamp - t);
      if (dt < max_dt) {
        candidates.push_back({dt, e, static_cast<std::size_t>(it - groundtruth.begin())});
      }
    }
  }
  // Ties broken by index so the result is deterministic.
  std::sort(candidates.begin(), candidates.end(), [](const Candidate& a, const Candidate& b) {
    return a.dt != b.dt ? a.dt < b.dt : (a.e != b.e ? a.e < b.e : a.g < b.g);
  });
  std::vector<char> estimate_taken(estimate.size(), 0);
  std::vector<char> groundtruth_taken(groundtruth.size(), 0);
  std::vector<AssociatedPair> pairs;
  for (const Candidate& c : candidates) {
    if (estimate_taken[c.e] || groundtruth_taken[c.g]) continue;
    estimate_taken[c.e] = groundtruth_taken[c.g] = 1;
    pairs.push_back({c.e, c.g});
  }
  std::sort(pairs.begin(), pairs.end(), [](const AssociatedPair& a, const AssociatedPair& b) {
    return a.estimate_index < b.estimate_index;
  });
  return pairs;
}

}  // namespace parallax
