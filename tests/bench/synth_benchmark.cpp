// Google Benchmark of the synthetic renderer (target: >= 30 frames/s at 640x480, one core).

#include <benchmark/benchmark.h>

#include "tools/synth/synthetic_sequence.hpp"

namespace parallax::synth {
namespace {

void BM_RenderFrame(benchmark::State& state, const char* scene_name) {
  SynthOptions options;
  options.scene = scene_name;
  const Scene scene = MakeScene(options.scene, options.seed);
  int index = 0;
  for (auto _ : state) {
    SynthFrame frame = RenderSynthFrame(options, scene, index++ % options.frames);
    benchmark::DoNotOptimize(frame.image.Data());
  }
  state.counters["fps"] =
      benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK_CAPTURE(BM_RenderFrame, room, "room")->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_RenderFrame, desk, "desk")->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_RenderFrame, corridor, "corridor")->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_RenderFrame, street, "street")->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace parallax::synth

BENCHMARK_MAIN();
