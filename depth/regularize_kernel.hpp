#pragma once
// The 5x5 regularisation of one inverse-depth estimate (LSD-SLAM's regularizeDepthMap, in the
// scale-free form of docs/math/depth_filter.md): an SSE2 kernel and its scalar twin, which add
// up the same terms in the same order and so give bit-identical results (a test compares
// them). The profile of real-texture sequences put this loop first (docs/benchmarks.md).

#include <array>
#include <cstddef>
#include <vector>

namespace parallax {

/// Per-pixel inputs of the regularisation (index = y * width + x), prepared once per pass so
/// that the kernel reads contiguous floats without branching on validity.
struct RegularizeInputs {
  int width = 0;
  const float* idepth = nullptr;
  const float* variance = nullptr;
  std::vector<float> inv_var;     ///< 1 / variance; 0 for invalid pixels
  std::vector<float> support;     ///< validity; 0 for invalid pixels
  std::vector<float> vote;        ///< validity of observed estimates (they vote); else 0
  std::array<float, 25> decay{};  ///< weight factor by offset ((dy + 2) * 5 + dx + 2)
};

/// What one pixel's window gives.
struct RegularizedPixel {
  float idepth = 0.0f;    ///< inverse-variance weighted mean of the compatible neighbours
  float variance = 0.0f;  ///< min(own variance, 1 / sum of weights)
  float support = 0.0f;   ///< sum of neighbours' validity (the pixel's own included)
  float agree = 0.0f;     ///< votes of compatible observed neighbours (not the pixel itself)
  float disagree = 0.0f;  ///< votes of incompatible observed neighbours
};

/// Regularises the valid pixel at index i (x, y at least 2 from the border). A neighbour j
/// is compatible when (d_j - d_i)^2 <= var_i + var_j; compatible ones are averaged with
/// weight inv_var_j * decay. Sums run over the columns dx = -2..1 as four lanes and dx = +2
/// apart, each down the rows, then ((lane0 + lane1) + (lane2 + lane3)) + column 5.
RegularizedPixel RegularizePixelScalar(const RegularizeInputs& in, std::size_t i);
/// The same with SSE2 (the scalar twin where SSE2 is not available).
RegularizedPixel RegularizePixelSimd(const RegularizeInputs& in, std::size_t i);

}  // namespace parallax
