#pragma once
// Numerical divergence (docs/reliability.md, "Divergence"): a value that went non-finite or
// out of its domain. The Lie groups throw it when built from such values (scale <= 0, a
// non-finite translation or rotation); inside an estimator that means the estimator
// diverged, and System catches it where a stage hands over its result, reports the event
// and goes on without that result. It is a std::invalid_argument, so code that builds a
// group from its caller's values reports bad input as before.

#include <cmath>
#include <stdexcept>
#include <string>

namespace parallax {

/// A value that diverged (NaN, infinite, scale <= 0).
class NumericalDivergence : public std::invalid_argument {
 public:
  explicit NumericalDivergence(const std::string& what) : std::invalid_argument(what) {}
};

/// A usable inverse-depth estimate: finite and positive, with a variance whose inverse is
/// finite and positive too (regularisation weights by 1 / variance).
inline bool HealthyEstimate(float idepth, float variance) {
  return std::isfinite(idepth) && idepth > 0.0f && std::isfinite(variance) && variance > 0.0f &&
         std::isfinite(1.0f / variance);
}

}  // namespace parallax
