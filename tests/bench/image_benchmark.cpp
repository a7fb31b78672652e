// Google Benchmark of PNG frame decoding (the frame reader's work per frame): the direct
// decoder (tools/dataset/png_direct.hpp) against libpng on the same file, file read included.

#include <benchmark/benchmark.h>
#include <unistd.h>

#include <filesystem>
#include <opencv2/core.hpp>
#include <string>

#include "tools/dataset/image_codecs.hpp"
#include "tools/dataset/image_file.hpp"
#include "tools/dataset/opencv_image.hpp"
#include "tools/synth/synthetic_sequence.hpp"

namespace parallax {
namespace {

/// A rendered 640x480 room frame as an 8-bit grey PNG, and the same with three slightly
/// different channels as an RGB PNG (libpng's writer, level 1, as `parallax synth` writes).
const std::string& FramePng(bool rgb) {
  static const std::string dir = [] {
    const auto d = std::filesystem::temp_directory_path() /
                   ("parallax_image_benchmark_" + std::to_string(::getpid()));
    std::filesystem::create_directories(d);
    synth::SynthOptions options;
    const synth::Scene scene = synth::MakeScene(options.scene, options.seed);
    const synth::SynthFrame frame = synth::RenderSynthFrame(options, scene, 10);
    const cv::Mat grey = GreyMatView(frame.image);
    WritePngFile((d / "grey.png").string(), grey);
    cv::Mat channels[3] = {grey.clone(), grey + 3, grey - 2};
    cv::Mat bgr;
    cv::merge(channels, 3, bgr);
    WritePngFile((d / "rgb.png").string(), bgr);
    return d.string();
  }();
  static const std::string grey = dir + "/grey.png", colour = dir + "/rgb.png";
  return rgb ? colour : grey;
}

void BM_DecodePngFrame(benchmark::State& state, bool rgb, codecs::PngDecoders decoders) {
  const std::string& file = FramePng(rgb);
  for (auto _ : state) {
    codecs::DecodeResult r =
        codecs::DecodePng(file, ImageReadMode::kGrey8, 1LL << 30, nullptr, decoders);
    if (r.status != codecs::DecodeStatus::kOk) state.SkipWithError("decode failed");
    benchmark::DoNotOptimize(r.pixels.data);
  }
}
BENCHMARK_CAPTURE(BM_DecodePngFrame, grey_direct, false, codecs::PngDecoders::kDirectFirst)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_DecodePngFrame, grey_libpng, false, codecs::PngDecoders::kLibpngOnly)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_DecodePngFrame, rgb_direct, true, codecs::PngDecoders::kDirectFirst)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_DecodePngFrame, rgb_libpng, true, codecs::PngDecoders::kLibpngOnly)
    ->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace parallax

BENCHMARK_MAIN();
