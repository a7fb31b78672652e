#pragma once
// Brute-force nearest neighbours of binary descriptors by Hamming distance: the two-view
// start's matching of every ORB feature against every other (docs/benchmarks.md, "The
// start's ORB matching").

#include <span>
#include <vector>

#include "backend/orb_features.hpp"

namespace parallax {

/// The nearest and second-nearest train descriptors of one query descriptor.
struct NearestTwo {
  int nearest = -1;  ///< train index; -1 when there is no train descriptor
  int nearest_distance = 0;
  int second = -1;  ///< train index; -1 when there are fewer than two
  int second_distance = 0;
};

/// For every query descriptor, its two nearest train descriptors by Hamming distance. Ties go
/// to the lower train index, so the result is what OpenCV's BFMatcher(NORM_HAMMING)::knnMatch
/// with k = 2 gives. Uses the CPU's popcount instruction where it has one; the result does
/// not depend on that or on the thread count.
std::vector<NearestTwo> NearestTwoByHamming(std::span<const OrbDescriptor> query,
                                            std::span<const OrbDescriptor> train);

/// The same, one query after another with the portable popcount: the twin the fast path is
/// tested against.
std::vector<NearestTwo> NearestTwoByHammingScalar(std::span<const OrbDescriptor> query,
                                                  std::span<const OrbDescriptor> train);

}  // namespace parallax
