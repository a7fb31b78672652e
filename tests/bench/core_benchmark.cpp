// Google Benchmarks of the per-frame core work: pyramid + gradients, and undistortion.
// Run: build/tests/bench/core_benchmark (results recorded in docs/benchmarks.md).

#include <benchmark/benchmark.h>

#include <random>

#include "core/image_pyramid.hpp"
#include "core/undistorter.hpp"

namespace parallax {
namespace {

ImageU8 RandomImage(int w, int h) {
  std::mt19937 rng(1);
  std::uniform_int_distribution<int> value(0, 255);
  ImageU8 image(w, h);
  for (std::size_t i = 0; i < image.NumPixels(); ++i) {
    image.Data()[i] = static_cast<std::uint8_t>(value(rng));
  }
  return image;
}

void BM_PyramidWithGradients(benchmark::State& state) {
  const ImageU8 image =
      RandomImage(static_cast<int>(state.range(0)), static_cast<int>(state.range(1)));
  for (auto _ : state) {
    ImagePyramid pyramid(image, PyramidOptions{});
    benchmark::DoNotOptimize(pyramid.Level(pyramid.NumLevels() - 1).dy.Data());
  }
}
BENCHMARK(BM_PyramidWithGradients)
    ->Args({640, 480})
    ->Args({1226, 370})
    ->Unit(benchmark::kMicrosecond);

void BM_Undistort(benchmark::State& state) {
  const int w = static_cast<int>(state.range(0));
  const int h = static_cast<int>(state.range(1));
  // fr1-like radial-tangential lens scaled to the image size.
  const double f = 0.81 * w;
  const Camera camera(CameraModel::kRadTan, w, h, f, f, 0.5 * w, 0.5 * h,
                      {0.262383, -0.953104, -0.005358, 0.002628, 1.163314});
  const Undistorter undistorter(camera, UndistorterOptions{});
  const ImageU8 image = RandomImage(w, h);
  ImageU8 output(undistorter.OutputCamera().Width(), undistorter.OutputCamera().Height());
  for (auto _ : state) {
    undistorter.Apply(image, &output);
    benchmark::DoNotOptimize(output.Data());
  }
}
BENCHMARK(BM_Undistort)->Args({640, 480})->Args({1226, 370})->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace parallax

BENCHMARK_MAIN();
