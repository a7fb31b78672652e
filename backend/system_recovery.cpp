// System: a frame lost on the current keyframe (recent keyframes, relocalisation on the
// whole map, a new map after long loss).
#include <memory>
#include <optional>
#include <shared_mutex>
#include <utility>
#include <vector>

#include "backend/system.hpp"
#include "core/divergence.hpp"

namespace parallax {

std::optional<TrackingResult> System::TrackRecentKeyframes(const Frame& frame,
                                                           FrameResult* result) {
  std::vector<RecoveryCandidate> candidates;
  for (std::size_t i = 0; i < mapper_.NumRecent(); ++i) {
    candidates.push_back({&mapper_.RecentReference(i), graph_.Pose(mapper_.RecentKeyframeId(i))});
  }
  const Sim3d S_w_last = CurrentKeyframePose() * Sim3d(tracker_.State().T_kf_last);
  std::optional<std::pair<std::size_t, TrackingResult>> found;
  try {
    found = tracker_.Recover(candidates, frame, S_w_last);
  } catch (const NumericalDivergence&) {
    ++backend_stats_.frames_diverged;
    result->events.push_back({SystemEvent::Kind::kDiverged, frame.Id(), current_.id});
  }
  if (!found) return std::nullopt;
  // The found keyframe becomes current again (its depth is refined further and frozen again
  // when it is left); the current one is finished and takes its place among the recent ones.
  const std::int64_t id = mapper_.RecentKeyframeId(found->first);
  FinishCurrentKeyframe(result);
  mapper_.ReturnTo(found->first);
  current_ = CurrentKeyframe{id, std::nullopt, Sim3d()};
  CompactOldKeyframes();
  return std::move(found->second);
}

std::optional<std::pair<std::shared_ptr<const Keyframe>, TrackingResult>> System::Relocalise(
    const Frame& frame, const ImageU8& image) {
  std::vector<RelocalizationGuess> guesses;
  {
    const std::shared_lock<std::shared_mutex> place(place_mutex_);
    if (!options_.relocalization.enabled || place_.Size() == 0) return std::nullopt;
    try {
      guesses = relocalizer_.Propose(graph_, place_, *place_.Describe(image));
    } catch (const NumericalDivergence&) {
      return std::nullopt;  // the frame stays lost
    }
  }
  ++backend_stats_.relocalisation_attempts;
  for (const RelocalizationGuess& guess : guesses) {
    const auto keyframe = Materialize(graph_.GetPtr(guess.keyframe_id), camera_, options_.pyramid,
                                      options_.reference);
    TrackingResult r;
    try {
      r = tracker_.TrackFrom(*keyframe->reference, frame, guess.T_kf_frame, AffineBrightness{});
    } catch (const NumericalDivergence&) {
      continue;  // as a confirmation that failed
    }
    if (!tracker_.Reacquires(r)) continue;
    ++backend_stats_.relocalisations;
    return std::make_pair(keyframe, std::move(r));
  }
  return std::nullopt;
}

void System::ReturnToKeyframe(const std::shared_ptr<const Keyframe>& keyframe,
                              FrameResult* result) {
  if (keyframe->id == current_.id) return;
  FinishCurrentKeyframe(result);
  std::optional<std::size_t> recent;
  for (std::size_t i = 0; i < mapper_.NumRecent(); ++i) {
    if (mapper_.RecentKeyframeId(i) == keyframe->id) recent = i;
  }
  if (recent) {
    mapper_.ReturnTo(*recent);
  } else {
    // Its map again from the frozen depth; hypotheses stay unconfirmed.
    InverseDepthMap map(keyframe->frame, options_.depth);
    ImageF idepth, variance;
    keyframe->depth.ToImages(&idepth, &variance);
    map.InitializeFromPrior(idepth, variance);
    for (std::size_t k = 0; k < keyframe->depth.Size(); ++k) {
      if (!keyframe->depth.confirmed[k]) {
        map.observations[static_cast<std::size_t>(keyframe->depth.pixel[k])] = 0;
      }
    }
    if (mapper_.HasMap()) mapper_.Retire();
    mapper_.SetMap(std::move(map));
    mapper_.Direction().Reset();
  }
  current_ = CurrentKeyframe{keyframe->id, std::nullopt, Sim3d()};
  current_map_ = graph_.MapOf(keyframe->id);
  CompactOldKeyframes();
}

FrameResult System::StartNewMap(const std::shared_ptr<const Frame>& frame, const ImageU8& image) {
  FrameResult finished;
  FinishCurrentKeyframe(&finished);
  mapper_.Clear();
  current_ = CurrentKeyframe{};
  ++map_generation_;
  current_map_ = next_map_++;
  ++backend_stats_.maps_started;
  start_ = StartState::kNoKeyframe;
  depth_updates_ = 0;
  lost_in_a_row_ = 0;
  initial_frames_.clear();
  EndPairSearch();
  pending_pair_.reset();
  FrameResult result = StartFirstKeyframe(frame, image);
  SystemEvent started{SystemEvent::Kind::kNewMap, frame->Id(),
                      result.is_keyframe ? frame->Id() : -1};
  started.map_id = current_map_;
  result.events.insert(result.events.begin(), started);
  result.events.insert(result.events.begin(), finished.events.begin(), finished.events.end());
  return result;
}

}  // namespace parallax
