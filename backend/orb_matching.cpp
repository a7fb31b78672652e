#include "backend/orb_matching.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <cstddef>
#include <cstdint>

namespace parallax {
namespace {

constexpr int kNoDistance = 257;  // more than any 256-bit Hamming distance

/// Keeps the two smallest distances seen in train order: a tie with the nearest goes
/// second, a tie with the second is not taken (as OpenCV's insertion into its k-best list).
inline void Consider(int distance, int index, NearestTwo* best) {
  if (distance >= best->second_distance) return;
  if (distance < best->nearest_distance) {
    best->second = best->nearest;
    best->second_distance = best->nearest_distance;
    best->nearest = index;
    best->nearest_distance = distance;
  } else {
    best->second = index;
    best->second_distance = distance;
  }
}

NearestTwo Unmatched() {
  NearestTwo none;
  none.nearest_distance = kNoDistance;
  none.second_distance = kNoDistance;
  return none;
}

/// Leaves the distances of missing neighbours at 0 as documented (nothing was found).
NearestTwo Finished(NearestTwo best) {
  if (best.nearest < 0) best.nearest_distance = 0;
  if (best.second < 0) best.second_distance = 0;
  return best;
}

NearestTwo SearchPortable(const OrbDescriptor& q, std::span<const OrbDescriptor> train) {
  NearestTwo best = Unmatched();
  for (std::size_t j = 0; j < train.size(); ++j)
    Consider(Hamming(q, train[j]), static_cast<int>(j), &best);
  return Finished(best);
}

// The same search compiled for the popcount instruction (called only where the CPU has it).
__attribute__((target("popcnt"))) NearestTwo SearchPopcnt(const OrbDescriptor& q,
                                                          std::span<const OrbDescriptor> train) {
  NearestTwo best = Unmatched();
  const std::uint64_t q0 = q[0], q1 = q[1], q2 = q[2], q3 = q[3];
  for (std::size_t j = 0; j < train.size(); ++j) {
    const OrbDescriptor& t = train[j];
    const int d = __builtin_popcountll(q0 ^ t[0]) + __builtin_popcountll(q1 ^ t[1]) +
                  __builtin_popcountll(q2 ^ t[2]) + __builtin_popcountll(q3 ^ t[3]);
    Consider(d, static_cast<int>(j), &best);
  }
  return Finished(best);
}

bool CpuHasPopcnt() {
  static const bool has = __builtin_cpu_supports("popcnt") != 0;
  return has;
}

}  // namespace

std::vector<NearestTwo> NearestTwoByHamming(std::span<const OrbDescriptor> query,
                                            std::span<const OrbDescriptor> train) {
  std::vector<NearestTwo> result(query.size());
  const bool popcnt = CpuHasPopcnt();
  // Each query's result depends on it alone: any split of the queries gives the same.
  constexpr std::size_t kGrain = 64;
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, query.size(), kGrain),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      for (std::size_t i = range.begin(); i < range.end(); ++i) {
                        result[i] = popcnt ? SearchPopcnt(query[i], train)
                                           : SearchPortable(query[i], train);
                      }
                    });
  return result;
}

std::vector<NearestTwo> NearestTwoByHammingScalar(std::span<const OrbDescriptor> query,
                                                  std::span<const OrbDescriptor> train) {
  std::vector<NearestTwo> result;
  result.reserve(query.size());
  for (const OrbDescriptor& q : query) result.push_back(SearchPortable(q, train));
  return result;
}

}  // namespace parallax
