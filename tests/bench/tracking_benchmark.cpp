// Google Benchmark of SE(3) tracking: one 640x480 frame against a keyframe with ~30k
// semi-dense points (rendered room, exact depth), plus the cost of one evaluation pass per
// level so the per-level split can be read off (docs/benchmarks.md).

#include <benchmark/benchmark.h>

#include "tests/tracking/render_fixture.hpp"
#include "tracking/se3_tracker.hpp"

namespace parallax {
namespace {

struct Fixture {
  Fixture() {
    const synth::Scene scene = synth::MakeScene("room", 3);
    synth::SynthOptions options;
    options.frames = 40;
    const test::RenderedKeyframe kf =
        test::RenderTestKeyframe(scene, synth::FramePose(options, scene, 0));
    // min_gradient 24 leaves ~30k level-0 points in this richly textured view, the size the
    // target is set for.
    TrackingReferenceOptions reference_options;
    reference_options.min_gradient = 24.0f;
    reference =
        std::make_unique<TrackingReference>(kf.frame, kf.idepth, kf.variance, reference_options);
    frame = test::RenderTestFrame(scene, synth::FramePose(options, scene, 3), 1);
    T_kf_frame = kf.T_w_c.Inverse() * synth::FramePose(options, scene, 3);
  }
  std::unique_ptr<TrackingReference> reference;
  std::shared_ptr<const Frame> frame;
  SE3d T_kf_frame;
};

const Fixture& GetFixture() {
  static const Fixture fixture;
  return fixture;
}

// Tracking from the previous frame's pose (the usual constant-position start).
void BM_TrackFrame(benchmark::State& state) {
  const Fixture& f = GetFixture();
  Se3TrackerOptions options;
  options.finest_level = static_cast<int>(state.range(0));
  Se3Tracker tracker(options);
  const SE3d guess =
      f.T_kf_frame *
      SE3d::Exp((Eigen::Matrix<double, 6, 1>() << 0.01, 0.0, 0.005, 0.0, 0.004, 0.0).finished());
  TrackingResult result;
  for (auto _ : state) {
    result = tracker.TrackFrom(*f.reference, *f.frame, guess, {});
    benchmark::DoNotOptimize(result);
  }
  state.counters["points_l0"] = static_cast<double>(f.reference->Level(0).Size());
  for (int l = 0; l < 5; ++l)
    state.counters["iters_l" + std::to_string(l)] =
        result.stats.iterations[static_cast<std::size_t>(l)];
}
BENCHMARK(BM_TrackFrame)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

// One residual + normal-equation pass over a level.
void BM_EvaluateLevel(benchmark::State& state) {
  const Fixture& f = GetFixture();
  Se3Tracker tracker;
  const int level = static_cast<int>(state.range(0));
  for (auto _ : state) {
    auto e = tracker.EvaluateLevel(*f.reference, *f.frame, level, f.T_kf_frame.Inverse(), {});
    benchmark::DoNotOptimize(e);
  }
  state.counters["points"] = static_cast<double>(f.reference->Level(level).Size());
}
BENCHMARK(BM_EvaluateLevel)->DenseRange(0, 4)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace parallax

BENCHMARK_MAIN();
