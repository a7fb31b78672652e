// Google Benchmark of one stereo update (and of the regularisation) of the inverse-depth filter: a
// 640x480 keyframe of the rendered room with a prior on its pixels (~50k active) and one frame 5 cm
// to the side.

#include <benchmark/benchmark.h>

#include "depth/depth_filter.hpp"
#include "tests/tracking/render_fixture.hpp"

namespace parallax {
namespace {

struct Fixture {
  Fixture() {
    const synth::Scene scene = synth::MakeScene("room", 3);
    synth::SynthOptions options;
    const SE3d T_w_kf = synth::FramePose(options, scene, 0);
    keyframe = std::make_unique<test::RenderedKeyframe>(test::RenderTestKeyframe(scene, T_w_kf));
    const SE3d T_w_f = T_w_kf * SE3d(SO3d(), Eigen::Vector3d(0.05, 0.03, 0.0));
    frame = test::RenderTestFrame(scene, T_w_f, 1);
    T_frame_kf = T_w_f.Inverse() * T_w_kf;
    map = std::make_unique<InverseDepthMap>(keyframe->frame, DepthFilterOptions{});
    ImageF variance(640, 480, 0.0f);
    for (std::size_t i = 0; i < variance.NumPixels(); ++i) {
      const float d = keyframe->idepth.Data()[i];
      variance.Data()[i] = (0.05f * d) * (0.05f * d);
    }
    map->InitializeFromPrior(keyframe->idepth, variance);
  }
  std::unique_ptr<test::RenderedKeyframe> keyframe;
  std::shared_ptr<const Frame> frame;
  SE3d T_frame_kf;
  std::unique_ptr<InverseDepthMap> map;
};

// Arg 0: the map as it is (49.9k pixels with a prior + 24.2k eligible pixels without, which
// get a full-range search; 58.6k + 26k with min_gradient 5). Arg 1: only the pixels with a
// prior are active (the "update of a map with ~50k active pixels" of the target), i.e. no
// creation searches.
void BM_StereoUpdate(benchmark::State& state) {
  static const Fixture f;
  const DepthFilter filter;
  DepthUpdateStats stats;
  InverseDepthMap base = *f.map;
  if (state.range(0) == 1) {
    for (std::size_t i = 0; i < base.valid.size(); ++i)
      base.eligible[i] = base.eligible[i] && base.valid[i];
  }
  for (auto _ : state) {
    state.PauseTiming();
    InverseDepthMap map = base;
    state.ResumeTiming();
    stats = filter.Update(&map, {f.frame.get(), f.T_frame_kf});
    benchmark::DoNotOptimize(map.idepth.data());
  }
  state.counters["valid_before"] = static_cast<double>(f.map->NumValid());
  state.counters["attempted"] = stats.attempted;
  state.counters["fused"] = stats.fused;
}
BENCHMARK(BM_StereoUpdate)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

/// Times `step` on a fresh copy of the fixture's map each iteration (the copy is not timed).
template <typename Step>
void OnMapCopies(benchmark::State& state, const Step& step) {
  static const Fixture f;
  for (auto _ : state) {
    state.PauseTiming();
    InverseDepthMap map = *f.map;
    state.ResumeTiming();
    step(&map);
    benchmark::DoNotOptimize(map.idepth_smoothed.data());
  }
}

// Regularisation alone (part of every update): the 5x5 smoothing and outlier vote over the
// ~50k valid pixels of the map.
void BM_Regularize(benchmark::State& state) {
  const DepthFilter filter;
  OnMapCopies(state, [&](InverseDepthMap* map) { filter.Regularize(map); });
}
BENCHMARK(BM_Regularize)->Unit(benchmark::kMillisecond);

// Keyframe creation's depth step: the map moved into a frame 5 cm away (projection, two
// regularisations and hole filling), and hole filling alone.
void BM_Propagate(benchmark::State& state) {
  static const Fixture f;
  const DepthFilter filter;
  const SE3d T_new_old = f.T_frame_kf;
  for (auto _ : state) {
    InverseDepthMap next = filter.Propagate(*f.map, f.frame, T_new_old, 1.0f, 0.0f);
    benchmark::DoNotOptimize(next.idepth.data());
  }
}
BENCHMARK(BM_Propagate)->Unit(benchmark::kMillisecond);

void BM_FillHoles(benchmark::State& state) {
  const DepthFilter filter;
  OnMapCopies(state,
              [&](InverseDepthMap* map) { benchmark::DoNotOptimize(filter.FillHoles(map)); });
}
BENCHMARK(BM_FillHoles)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace parallax

BENCHMARK_MAIN();
