// Place recognition costs: ORB extraction, vocabulary lookup per keyframe, a database query
// at 1,000 keyframes, ORB matching by nodes, Sim(3) RANSAC, and a whole loop closure of a
// true revisit (query, verification, loop edge and optimisation).

#include <benchmark/benchmark.h>

#include <cstring>
#include <opencv2/features2d.hpp>
#include <random>

#include "backend/loop_closer.hpp"
#include "backend/orb_matching.hpp"
#include "backend/place_recognizer.hpp"
#include "backend/sim3_ransac.hpp"
#include "tests/backend/revisit_fixture.hpp"
#include "tests/tracking/render_fixture.hpp"
#include "tools/synth/motion.hpp"
#include "tools/synth/scene.hpp"

namespace parallax {
namespace {

ImageU8 View(double t) {
  static const synth::Scene scene = synth::MakeScene("room", 5);
  return test::RenderTestImage(scene, synth::CameraPose(synth::Motion::kOrbit, scene.rig, t, 1.0));
}

void BM_OrbExtract640x480(benchmark::State& state) {
  const ImageU8 image = View(0.1);
  for (auto _ : state) benchmark::DoNotOptimize(ExtractOrb(image));
}
BENCHMARK(BM_OrbExtract640x480)->Unit(benchmark::kMillisecond);

/// The two-view start's matching: 1,500 ORB features of one view against another's, the
/// nearest two of each (arg 0: NearestTwoByHamming; 1: OpenCV's BFMatcher::knnMatch, which it
/// replaced with the same result).
void BM_StartMatching(benchmark::State& state) {
  const OrbOptions options{.max_features = 1500};
  const OrbFeatures a = ExtractOrb(View(0.10), options), b = ExtractOrb(View(0.12), options);
  const auto rows = [](const std::vector<OrbDescriptor>& d) {
    cv::Mat m(static_cast<int>(d.size()), 32, CV_8U);
    for (std::size_t i = 0; i < d.size(); ++i)
      std::memcpy(m.ptr(static_cast<int>(i)), d[i].data(), sizeof(OrbDescriptor));
    return m;
  };
  const cv::Mat rows_a = rows(a.descriptors), rows_b = rows(b.descriptors);
  std::vector<std::vector<cv::DMatch>> knn;
  for (auto _ : state) {
    if (state.range(0) == 0) {
      benchmark::DoNotOptimize(NearestTwoByHamming(a.descriptors, b.descriptors));
    } else {
      cv::BFMatcher(cv::NORM_HAMMING).knnMatch(rows_a, rows_b, knn, 2);
      benchmark::DoNotOptimize(knn.data());
    }
  }
  state.counters["features"] = static_cast<double>(a.Size());
}
BENCHMARK(BM_StartMatching)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

void BM_VocabularyTransformPerKeyframe(benchmark::State& state) {
  const OrbFeatures features = ExtractOrb(View(0.1));
  FeatureVector direct;
  for (auto _ : state) {
    benchmark::DoNotOptimize(Vocabulary::Default().Transform(features.descriptors, &direct, 2));
  }
  state.counters["features"] = static_cast<double>(features.Size());
}
BENCHMARK(BM_VocabularyTransformPerKeyframe)->Unit(benchmark::kMillisecond);

/// A database of `keyframes` entries: descriptors of 40 rendered views round the orbit, each
/// keyframe a copy of one with 20% of its descriptors' bits perturbed (distinct vectors).
void BM_DatabaseQuery(benchmark::State& state) {
  const auto keyframes = static_cast<int>(state.range(0));
  std::vector<std::vector<OrbDescriptor>> views;
  views.reserve(40);
  for (int v = 0; v < 40; ++v) views.push_back(ExtractOrb(View(v / 40.0)).descriptors);
  std::mt19937_64 random(1);
  KeyframeDatabase database;
  for (int k = 0; k < keyframes; ++k) {
    std::vector<OrbDescriptor> d = views[static_cast<std::size_t>(k % 40)];
    for (auto& descriptor : d) {
      if (random() % 5 == 0) descriptor[random() % 4] ^= random();
    }
    database.Add(k, Vocabulary::Default().Transform(d));
  }
  const BowVector query = Vocabulary::Default().Transform(ExtractOrb(View(0.013)).descriptors);
  for (auto _ : state) benchmark::DoNotOptimize(database.Query(query, {}, 3));
}
BENCHMARK(BM_DatabaseQuery)->Arg(100)->Arg(1000)->Unit(benchmark::kMillisecond);

void BM_MatchByNodes(benchmark::State& state) {
  const PlaceRecognizer recognizer(Vocabulary::Default());
  const auto a = recognizer.Describe(View(0.1));
  const auto b = recognizer.Describe(View(0.11));
  for (auto _ : state) benchmark::DoNotOptimize(MatchByNodes(*a, *b, recognizer.Options()));
}
BENCHMARK(BM_MatchByNodes)->Unit(benchmark::kMillisecond);

void BM_Sim3Ransac200Matches40PercentOutliers(benchmark::State& state) {
  const PinholeCamera camera(640, 480, 500.0, 500.0, 319.5, 239.5);
  const Sim3d S(1.3, SO3d::Exp(Eigen::Vector3d(0.02, -0.3, 0.01)), Eigen::Vector3d(0.4, 0, 0.1));
  std::mt19937_64 random(2);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<PointMatch3d> matches;
  while (matches.size() < 200) {
    PointMatch3d m;
    m.px_b = Eigen::Vector2d(20 + 600 * u(random), 20 + 440 * u(random));
    m.p_b = camera.Unproject(m.px_b) * (1.0 + 3.0 * u(random));
    m.p_a = S * m.p_b;
    if (m.p_a.z() < 0.1) continue;
    m.px_a = camera.Project(m.p_a);
    if (matches.size() < 80) m.p_a += Eigen::Vector3d(u(random), u(random), u(random));
    matches.push_back(m);
  }
  for (auto _ : state) benchmark::DoNotOptimize(EstimateSim3Ransac(matches, camera, {}));
}
BENCHMARK(BM_Sim3Ransac200Matches40PercentOutliers)->Unit(benchmark::kMillisecond);

/// LoopCloser::KeyframeFinished on a 13-keyframe orbit graph whose last keyframe revisits
/// the first (tests/backend/revisit_fixture.hpp): the database query, the verification of
/// the candidate (ORB matches lifted with both keyframes' depth, Sim(3) RANSAC, direct Sim(3)
/// alignment both ways, which rebuilds both compacted keyframes' pyramids and tracking
/// references), the loop edge and the graph's optimisation. The consistency gate is set to
/// one keyframe (it is bookkeeping); the graph is copied outside the timing.
void BM_LoopClosureOfATrueRevisit(benchmark::State& state) {
  const SystemOptions options;
  const test::Revisit revisit = test::MakeRevisit(options);
  GraphBackend backend(options.backend, revisit.build);
  LoopClosureOptions loop = options.loop_closure;
  loop.consistency = 1;
  for (auto _ : state) {
    state.PauseTiming();
    KeyframeGraph graph = revisit.graph;
    LoopCloser closer(loop, revisit.recognizer.get(), revisit.build.camera);
    state.ResumeTiming();
    const LoopReport report = closer.KeyframeFinished(&graph, &backend, revisit.revisit_id);
    if (!report.loop_keyframe) state.SkipWithError("the revisit was not closed");
  }
}
BENCHMARK(BM_LoopClosureOfATrueRevisit)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace parallax

BENCHMARK_MAIN();
