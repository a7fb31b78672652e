#pragma once
// Numerical divergence (docs/reliability.md, "Divergence"): a value that went non-finite or
// out of its domain. The Lie groups throw it when built from such values (scale <= 0, a
// non-finite translation or rotation); inside an estimator that means the estimator
// diverged, and System catches it where a stage hands over its result, reports the event
// and goes on without that result. It is a std::invalid_argument, so code that builds a
// group from its caller's values reports bad input as before.

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace parallax {

/// A value that diverged (NaN, infinite, scale <= 0).
class NumericalDivergence : public std::invalid_argument {
 public:
  explicit NumericalDivergence(const std::string& what) : std::invalid_argument(what) {}
};

/// A usable inverse-depth estimate: finite and positive, with a variance whose inverse is
/// finite and positive too (regularisation weights by 1 / variance). `inverse_variance` is
/// 1 / variance, passed in by loops that have it already. Branch-free (NaN fails every
/// comparison), so that such loops vectorise.
inline bool HealthyEstimate(float idepth, float variance, float inverse_variance) {
  constexpr float kMax = std::numeric_limits<float>::max();
  return static_cast<bool>(static_cast<int>(idepth > 0.0f) & static_cast<int>(idepth <= kMax) &
                           static_cast<int>(variance > 0.0f) & static_cast<int>(variance <= kMax) &
                           static_cast<int>(inverse_variance <= kMax));
}

inline bool HealthyEstimate(float idepth, float variance) {
  return HealthyEstimate(idepth, variance, 1.0f / variance);
}

}  // namespace parallax
