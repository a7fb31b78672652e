#pragma once
// The rendered room orbit the pipeline tests run on (tools/synth).

#include <cstdint>

#include "tools/synth/synthetic_sequence.hpp"

namespace parallax::test {

/// Options of the room orbit of `frames` frames rendered with `seed`.
inline synth::SynthOptions RoomOrbit(int frames, std::uint64_t seed) {
  synth::SynthOptions options;
  options.scene = "room";
  options.motion = "orbit";
  options.frames = frames;
  options.seed = seed;
  return options;
}

}  // namespace parallax::test
