#pragma once
// Scanning a row of a byte mask (valid or eligible pixels) that is mostly zero in runs: a
// per-pixel test is a branch the processor cannot predict, so runs of eight zero bytes are
// skipped with one 64-bit comparison.

#include <algorithm>
#include <cstdint>
#include <cstring>

namespace parallax {

/// Calls visit(x) for every x in [begin, end) except those in groups of eight consecutive
/// columns, counted from `begin`, whose mask bytes are all zero. Within a group that has a
/// non-zero byte every column is visited, so `visit` still tests mask[x] itself (or relies
/// on a test of its own). Precondition: mask[begin, end) is readable.
template <typename Visit>
inline void ForEachColumnNearMask(const std::uint8_t* mask, int begin, int end, Visit&& visit) {
  for (int x0 = begin; x0 < end; x0 += 8) {
    const int x1 = std::min(x0 + 8, end);
    std::uint64_t eight = 1;  // a partial last group is always visited
    if (x1 - x0 == 8) std::memcpy(&eight, mask + x0, sizeof(eight));
    if (eight == 0) continue;
    for (int x = x0; x < x1; ++x) visit(x);
  }
}

}  // namespace parallax
