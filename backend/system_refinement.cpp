// System: joint photometric refinement of a keyframe's depth with the frames that saw it,
// at the start and when a keyframe is left (docs/math/keyframe_refinement.md).

#include <algorithm>
#include <cstdint>
#include <vector>

#include "backend/system.hpp"

namespace parallax {
namespace {

/// The map's estimates: level-0 pixel indices and smoothed inverse depths.
void Estimates(const InverseDepthMap& map, std::vector<std::int32_t>* pixel,
               std::vector<float>* idepth) {
  for (std::size_t i = 0; i < map.valid.size(); ++i) {
    if (map.valid[i] == 0) continue;
    pixel->push_back(static_cast<std::int32_t>(i));
    idepth->push_back(map.idepth_smoothed[i]);
  }
}

}  // namespace

void System::RefineStart(BufferedPoses* poses) {
  if (!options_.start_refinement.enabled) return;
  InverseDepthMap& map = mapper_.Map();
  std::vector<std::int32_t> pixel;
  std::vector<float> idepth;
  Estimates(map, &pixel, &idepth);
  // At most max_frames buffered frames, spread over the window with the last (the widest
  // baseline) included: the joint problem's cost grows with the square of its frames.
  std::vector<std::size_t> posed;
  for (std::size_t i = 0; i < poses->size(); ++i) {
    if ((*poses)[i]) posed.push_back(i);
  }
  if (posed.size() < 2 || options_.start_refinement_frames < 2) return;
  std::vector<RefinementFrame> frames;
  std::vector<std::size_t> index;
  for (const std::size_t k :
       SpreadIndices(posed.size(), static_cast<std::size_t>(options_.start_refinement_frames))) {
    const std::size_t i = posed[k];
    frames.push_back({initial_frames_[i].first.get(), *(*poses)[i]});
    index.push_back(i);
  }
  const KeyframeRefinementResult r =
      RefineKeyframe(map.Keyframe(), pixel, idepth, frames, options_.start_refinement);
  SetEstimates(pixel, r.idepth, r.idepth);
  // Every buffered frame tracked against the refined depth (the refined poses as guesses).
  for (std::size_t j = 0; j < index.size(); ++j) (*poses)[index[j]] = r.T_kf_frame[j];
  std::optional<TrackingResult> previous;
  for (const std::size_t i : posed) {
    previous = TrackAgain(*initial_frames_[i].first, *(*poses)[i], previous);
    if (previous) (*poses)[i] = previous->T_kf_frame;
  }
}

void System::SetEstimates(const std::vector<std::int32_t>& pixel, const std::vector<float>& raw,
                          const std::vector<float>& smoothed) {
  InverseDepthMap& map = mapper_.Map();
  for (std::size_t k = 0; k < pixel.size(); ++k) {
    map.idepth[static_cast<std::size_t>(pixel[k])] = raw[k];
    map.idepth_smoothed[static_cast<std::size_t>(pixel[k])] = smoothed[k];
  }
  mapper_.PublishReference();
}

void System::RefineLeavingKeyframe() {
  const bool applies =
      options_.keyframe_refinement.enabled && window_.KeyframeId() == mapper_.KeyframeId() &&
      window_.FramesSeen() >= static_cast<std::size_t>(options_.keyframe_refinement_min_window);
  if (!applies) {
    window_.Clear();
    return;
  }
  InverseDepthMap& map = mapper_.Map();
  std::vector<std::int32_t> pixel;
  std::vector<float> idepth;
  Estimates(map, &pixel, &idepth);
  const std::vector<RefinementFrame> frames =
      window_.Select(static_cast<std::size_t>(options_.keyframe_refinement_frames));
  const KeyframeRefinementResult r =
      RefineKeyframe(map.Keyframe(), pixel, idepth, frames, options_.keyframe_refinement);
  window_.Clear();
  // The refined values become the filter's estimates and are regularised again, as after a
  // depth update (writing them into the smoothed map too measured worse: docs/benchmarks.md,
  // "Refining every keyframe").
  for (std::size_t k = 0; k < pixel.size(); ++k) {
    map.idepth[static_cast<std::size_t>(pixel[k])] = r.idepth[k];
  }
  mapper_.Filter().Regularize(&map);
  // The frames' refined poses are not used: the keyframe that follows starts from its
  // tracked pose (moving it too made the result depend more on which frames the window
  // held: docs/benchmarks.md, "Refining every keyframe").
}

}  // namespace parallax
