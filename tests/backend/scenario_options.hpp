#pragma once
// Options that keep an end-to-end test's scenario where it was measured. Some tests need a
// particular event on a particular render (a loop found only by the last keyframe, a heading
// correction spread over the chain, candidates that reach verification); a change of the
// keyframe rule moves every keyframe and can take the event away without anything being
// wrong. Such tests pin the rule they were built with here, and say so.

#include "backend/system_options.hpp"

namespace parallax::test {

/// The keyframe rule and update-direction gate before 2026-12-05 (eleventh session): the
/// relative distance |t| E[rho], no turn bound, a 3-degree gate (docs/math/keyframe_rule.md).
inline SystemOptions WithRelativeKeyframeRule(SystemOptions options = {}) {
  options.keyframe_distance_in_image = false;
  options.keyframe_rotation_deg = 0.0;
  options.update_direction.max_angle_deg = 3.0;
  return options;
}

}  // namespace parallax::test
