#pragma once
// A keyframe graph round a rendered room orbit that comes back to its start, for loop
// closure's unit test and benchmark: keyframes every 30 degrees with ground-truth depth,
// drift injected along the chain (odometry edges agree with the drifted poses), and a last
// keyframe a few degrees past the first one.

#include <cmath>
#include <memory>

#include "backend/keyframe_graph.hpp"
#include "backend/place_recognizer.hpp"
#include "backend/system_options.hpp"
#include "tests/tracking/render_fixture.hpp"
#include "tools/synth/motion.hpp"
#include "tools/synth/scene.hpp"

namespace parallax::test {

struct Revisit {
  KeyframeGraph graph;
  std::unique_ptr<PlaceRecognizer> recognizer;
  KeyframeBuildOptions build{TestCamera(), {}, {}};
  std::int64_t revisit_id = 0;
  Sim3d S_first_revisit_true;  ///< the true relative pose of the loop (metric depth: scale 1)
};

/// The first keyframe's pose is exact; keyframe k is off by k times a small rotation,
/// translation and scale step (about 1.4 degrees, 8 cm and 2.4% at the revisit).
inline Revisit MakeRevisit(const SystemOptions& options, int chain = 12) {
  static const synth::Scene scene = synth::MakeScene("room", 5);
  Revisit r;
  r.build.pyramid = options.pyramid;
  r.build.reference = options.reference;
  r.build.reference.finest_level =
      std::min(options.tracker.finest_level, options.backend.alignment.finest_level);
  r.recognizer =
      std::make_unique<PlaceRecognizer>(Vocabulary::Default(), options.loop_closure.place);
  const Sim3d drift_step(1.002, SO3d::Exp(Eigen::Vector3d(0.0005, 0.002, 0.0)),
                         Eigen::Vector3d(0.006, 0.0, 0.003));
  Sim3d drift;
  Sim3d previous;
  SE3d T_w_first;
  for (int k = 0; k <= chain; ++k) {
    // The last keyframe is 4 degrees past the start of the lap.
    const double t = k < chain ? static_cast<double>(k) / chain : 1.0 + 4.0 / 360.0;
    const SE3d T_w_c = synth::CameraPose(synth::Motion::kOrbit, scene.rig, t, 1.0);
    const RenderedKeyframe rendered = RenderTestKeyframe(scene, T_w_c);
    auto kf = std::make_shared<Keyframe>();
    kf->id = k;
    kf->timestamp = k;
    kf->image = RenderTestImage(scene, T_w_c, 1.0f, 0.0, 99);
    kf->depth.width = rendered.idepth.Width();
    kf->depth.height = rendered.idepth.Height();
    for (int y = 0; y < rendered.idepth.Height(); ++y) {
      for (int x = 0; x < rendered.idepth.Width(); ++x) {
        if (rendered.idepth(x, y) <= 0.0f) continue;
        kf->depth.pixel.push_back(y * rendered.idepth.Width() + x);
        kf->depth.idepth.push_back(rendered.idepth(x, y));
        kf->depth.variance.push_back(rendered.variance(x, y));
        kf->depth.confirmed.push_back(1);
      }
    }
    const Sim3d S_w_kf = Sim3d(T_w_c) * drift;
    r.graph.Upsert(kf, S_w_kf);
    r.recognizer->Add(k, r.recognizer->Describe(kf->image));
    if (k > 0) {
      PoseGraphEdge edge;
      edge.i = k - 1;
      edge.j = k;
      edge.S_i_j = previous.Inverse() * S_w_kf;
      edge.information = Matrix7d::Identity() * 1e4;
      r.graph.AddEdge(edge);
    } else {
      T_w_first = T_w_c;
    }
    if (k == chain) r.S_first_revisit_true = Sim3d(T_w_first.Inverse() * T_w_c);
    previous = S_w_kf;
    drift = drift * drift_step;
  }
  r.revisit_id = chain;
  return r;
}

}  // namespace parallax::test
