#pragma once
// Wall time of a stage for the statistics (steady clock; not a benchmark: docs/benchmarks.md).

#include <chrono>

namespace parallax {

using StageClock = std::chrono::steady_clock;

/// Milliseconds from `start` to now.
inline double MillisecondsSince(StageClock::time_point start) {
  return std::chrono::duration<double, std::milli>(StageClock::now() - start).count();
}

}  // namespace parallax
