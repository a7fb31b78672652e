#pragma once
// Rounding without a library call in per-pixel loops.

#include <cmath>

namespace parallax {

/// The same integer as std::lround(x) (halves away from zero), inlined: x - trunc(x) is exact
/// in float, so the comparison with 0.5 decides exactly as lround does. Precondition: |x| <
/// 2^31 (tests/core/rounding_test.cpp compares it with std::lround).
inline int RoundHalfAwayFromZero(float x) {
  const int t = static_cast<int>(x);
  const float fraction = x - static_cast<float>(t);
  if (fraction >= 0.5f) return t + 1;
  if (fraction <= -0.5f) return t - 1;
  return t;
}

}  // namespace parallax
