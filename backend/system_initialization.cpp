// System: the start of a sequence (design.md section 3a, docs/configuration.md).

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <utility>

#include "backend/system.hpp"
#include "core/angles.hpp"

namespace parallax {
namespace {

std::optional<SE3d> PoseOf(const std::optional<TrackingResult>& tracked) {
  if (!tracked) return std::nullopt;
  return tracked->T_kf_frame;
}

}  // namespace

FrameResult System::StartFirstKeyframe(const std::shared_ptr<const Frame>& frame,
                                       const ImageU8& image) {
  FrameResult result;
  InverseDepthMap map(frame, options_.depth);
  const auto textured = static_cast<double>(map.NumEligible());
  if (textured < options_.min_start_texture * static_cast<double>(image.NumPixels())) {
    // A covered lens, a dark room or a blank wall: no keyframe, no pose; try the next frame.
    result.stats.reason = "too little texture to start";
    return result;
  }
  if (options_.initialization == Initialization::kTwoView) {
    // Keyframe with an empty map; its depth comes from the first good two-view pair.
    StartKeyframe(frame, Sim3d(), std::move(map), &result);
    bootstrap_ = std::make_unique<TwoViewBootstrap>(camera_, options_.bootstrap);
    bootstrap_->SetReference(image);
    bootstrap_tries_ = 0;
    start_ = StartState::kTwoViewSearch;
  } else {
    StartRandom(frame, image, std::move(map), &result);
  }
  result.status = TrackingStatus::kOk;
  SetPose(&result, SE3d());
  result.is_keyframe = true;
  return result;
}

void System::StartRandom(const std::shared_ptr<const Frame>& frame, const ImageU8& image,
                         InverseDepthMap map, FrameResult* result) {
  // LSD-style start: random inverse depth (mean 1) that the first frames refine.
  map.InitializeRandom(1.0f);
  StartKeyframe(frame, Sim3d(), std::move(map), result);
  depth_updates_ = 0;
  lost_in_a_row_ = 0;
  EndPairSearch();
  start_ = StartState::kConverging;
  if (options_.initialization == Initialization::kAuto) {
    bootstrap_ = std::make_unique<TwoViewBootstrap>(camera_, options_.bootstrap);
    bootstrap_->SetReference(image);
    bootstrap_tries_ = 0;
    start_ = StartState::kRandomPairSearch;
  }
}

void System::BufferInitialFrame(const std::shared_ptr<const Frame>& frame, const SE3d& T_kf_frame) {
  initial_frames_.emplace_back(frame, T_kf_frame);
  // A camera that does not move before initialisation would otherwise buffer every frame
  // (a few MB each); the oldest keep the pose they were given, or stay without one.
  std::size_t pyramid_bytes = 0;
  for (int l = 0; l < frame->NumLevels(); ++l) {
    // intensity, dx, dy (level 0's gradients are computed if the frame becomes a keyframe)
    const PyramidLevel& level = frame->IntensityLevel(l);
    pyramid_bytes += static_cast<std::size_t>(level.Width() * level.Height()) * 3 * sizeof(float);
  }
  const auto by_bytes = static_cast<std::size_t>(options_.max_buffered_megabytes * 1e6 /
                                                 static_cast<double>(pyramid_bytes));
  const std::size_t limit = std::max<std::size_t>(
      1, std::min(by_bytes, static_cast<std::size_t>(options_.max_buffered_frames)));
  if (initial_frames_.size() > limit) {
    initial_frames_.erase(initial_frames_.begin());
  }
}

std::optional<TrackingResult> System::TrackAgain(const Frame& frame, const SE3d& guess,
                                                 const std::optional<TrackingResult>& previous) {
  TrackingResult again =
      tracker_.Retrack(*mapper_.Reference(), frame, guess, tracker_.State().affine);
  // Consecutive frames see nearly the same points: a result that explains clearly fewer than
  // the frame before it did is in another basin, which the guess may have led it into
  // (docs/math/tracking.md, "Tracking the start's frames again from the frame before").
  const double margin = options_.tracker.refine_margin;
  if (previous && (again.status == TrackingStatus::kLost ||
                   again.stats.points_good < (1.0 - margin) * previous->stats.points_good)) {
    TrackingResult from_previous =
        tracker_.Retrack(*mapper_.Reference(), frame, previous->T_kf_frame, previous->affine);
    if (ExplainsMore(from_previous, again, margin * again.stats.points_in_view)) {
      again = std::move(from_previous);
    }
  }
  if (again.status == TrackingStatus::kLost) return std::nullopt;
  return again;
}

std::vector<RevisedPose> System::FinishInitialisation() {
  std::vector<RevisedPose> revised;
  bool replaced = false;
  std::optional<BufferedPoses> poses;  // the buffered frames tracked against the final map
  if (start_ == StartState::kRandomPairHeld) {
    // The converged random start must agree with the independent two-view geometry; if it
    // does, the pair's start refined by the same frames is kept (KeepTheBetterStart).
    const auto& [pair_frame, pair] = *pending_pair_;
    SE3d guess;
    for (const auto& [frame, T_kf_frame] : initial_frames_) {
      if (frame == pair_frame) guess = T_kf_frame;
    }
    // One coarse-to-fine run (not Retrack): the random start's own answer is what is judged.
    const TrackingResult pair_again =
        tracker_.TrackFrom(*mapper_.Reference(), *pair_frame, guess, tracker_.State().affine);
    if (pair_again.status == TrackingStatus::kLost ||
        !RandomStartAgrees(pair_again.T_kf_frame, pair)) {
      revised = StartFromPair(pair_frame, pair);
      replaced = true;
    } else {
      // Geometry agrees: the refined pair (or, with a residual comparison, the better one).
      poses = KeepTheBetterStart(pair_frame, pair);
    }
    pending_pair_.reset();
  }
  if (!replaced) {
    if (!poses) {
      poses.emplace();
      std::optional<TrackingResult> previous;
      for (const auto& [frame, T_kf_frame] : initial_frames_) {
        previous = TrackAgain(*frame, T_kf_frame, previous);
        poses->push_back(PoseOf(previous));
      }
    }
    RefineStart(&*poses);
    for (std::size_t i = 0; i < initial_frames_.size(); ++i) {
      revised.push_back(Revised(*initial_frames_[i].first, (*poses)[i]));
    }
  }
  initial_frames_.clear();
  EndPairSearch();
  start_ = StartState::kInitialised;
  ++map_generation_;
  if (initialised_at_frame_ < 0) {  // the first map's
    initialised_at_frame_ = static_cast<int>(result_frame_id_ - first_frame_id_);
  }
  return revised;
}

FrameResult System::ProcessTwoViewOnly(const std::shared_ptr<const Frame>& frame,
                                       const ImageU8& image) {
  FrameResult result;
  BufferInitialFrame(frame, SE3d());
  if (const auto pair = bootstrap_->TryFrame(image)) {
    result.revised = StartFromPair(frame, *pair);
    TakeNewestRevision(&result);
    return result;
  }
  result.stats.reason = "initialising";
  if (++bootstrap_tries_ >= options_.bootstrap_max_frames) {
    // No usable pair: start over from random depth at this frame; the frames before it stay
    // without a pose.
    initial_frames_.clear();
    StartRandom(frame, image, InverseDepthMap(frame, options_.depth), &result);
    result.status = TrackingStatus::kOk;
    SetPose(&result, SE3d());
    result.is_keyframe = true;
  }
  return result;
}

std::optional<FrameResult> System::ProcessWhileInitialising(
    const std::shared_ptr<const Frame>& frame, const ImageU8& image,
    const TrackingResult& tracked) {
  // The exposure is still settling (an auto-exposure after a dark start): the first
  // keyframe no longer looks like the scene, and the tracker's brightness range will soon be
  // exceeded. Start again on this frame.
  if (tracked.status != TrackingStatus::kLost &&
      std::abs(tracked.affine.a) > std::log(options_.max_start_exposure_change)) {
    return RestartStart(frame, image);
  }
  if (start_ == StartState::kRandomPairSearch) {
    std::optional<TwoViewPair> fallback;
    if (const auto pair = bootstrap_->TryFrame(image, &fallback)) {
      pending_pair_.emplace(frame, *pair);
      EndPairSearch();
      start_ = StartState::kRandomPairHeld;
    } else if (++bootstrap_tries_ >= options_.bootstrap_max_frames) {
      EndPairSearch();
      start_ = StartState::kConverging;
    } else if (fallback &&
               (!fallback_pair_ || fallback->parallax_deg > fallback_pair_->second.parallax_deg)) {
      fallback_pair_.emplace(frame, *fallback);
    }
  }
  if (tracked.status == TrackingStatus::kOk) {
    lost_in_a_row_ = 0;
    return std::nullopt;
  }
  FrameResult result;
  result.stats = tracked.stats;
  if (start_ == StartState::kRandomPairHeld) {
    // The random start is failing and a pair is at hand: start from the pair now.
    BufferInitialFrame(frame, tracker_.State().T_kf_last);
    result.revised = StartFromPair(pending_pair_->first, pending_pair_->second);
    pending_pair_.reset();
    TakeNewestRevision(&result);
    return result;
  }
  if (tracked.status == TrackingStatus::kPoor) return std::nullopt;
  if (start_ == StartState::kRandomPairSearch && fallback_pair_) {
    // The random start is lost before any pair had enough parallax (forward motion: the
    // parallax can peak below the bound and fall again): the best pair so far beats waiting
    // for a restart that withdraws every pose (docs/configuration.md).
    const auto [pair_frame, pair] = *fallback_pair_;
    BufferInitialFrame(frame, tracker_.State().T_kf_last);
    result.revised = StartFromPair(pair_frame, pair);
    TakeNewestRevision(&result);
    return result;
  }
  result.status = TrackingStatus::kLost;
  // Lost frames wait (a pair may still be found for them); after restart_after_lost in a row
  // a restart is the way out, also while a pair is sought: a start on a bad first frame
  // otherwise stays lost for as long as the pair search lasts.
  if (++lost_in_a_row_ < options_.restart_after_lost) {
    BufferInitialFrame(frame, tracker_.State().T_kf_last);  // tried again when initialised
    return result;
  }
  return RestartStart(frame, image);
}

void System::EndPairSearch() {
  bootstrap_.reset();
  fallback_pair_.reset();
}

FrameResult System::RestartStart(const std::shared_ptr<const Frame>& frame, const ImageU8& image) {
  // The start has failed: withdraw every pose given so far and start again here.
  std::vector<RevisedPose> withdrawn;
  withdrawn.push_back(Revised(*mapper_.Map().KeyframePtr(), std::nullopt));
  for (const auto& buffered : initial_frames_) {
    withdrawn.push_back(Revised(*buffered.first, std::nullopt));
  }
  initial_frames_.clear();
  EndPairSearch();
  pending_pair_.reset();
  ClearMap();
  start_ = StartState::kNoKeyframe;
  FrameResult restarted = StartFirstKeyframe(frame, image);
  restarted.revised = std::move(withdrawn);
  restarted.events.insert(restarted.events.begin(),
                          {SystemEvent::Kind::kRestarted, frame->Id(), frame->Id()});
  return restarted;
}

void System::TakeNewestRevision(FrameResult* result) const {
  const RevisedPose newest = result->revised.back();
  result->revised.pop_back();
  result->status = newest.T_w_c ? TrackingStatus::kOk : TrackingStatus::kLost;
  if (newest.T_w_c) SetPose(result, newest.T_kf_frame);
}

bool System::RandomStartAgrees(const SE3d& T_kf_frame, const TwoViewPair& pair) const {
  const SE3d T_kf_pair = pair.T_frame_ref.Inverse();
  const double rotation_deg =
      (T_kf_frame.Rotation().Inverse() * T_kf_pair.Rotation()).Log().norm() * kRadToDeg;
  const double direction_deg = AngleBetweenDeg(T_kf_frame.Translation(), T_kf_pair.Translation());
  return rotation_deg < options_.auto_max_rotation_deg &&
         direction_deg < options_.auto_max_direction_deg;
}

std::vector<RevisedPose> System::StartFromPair(const std::shared_ptr<const Frame>& pair_frame,
                                               const TwoViewPair& pair) {
  // Stereo with the pair's pose creates the keyframe's depth from scratch (full-range
  // searches); the scale is normalised and the frames seen so far are tracked against it.
  InverseDepthMap map(mapper_.Map().KeyframePtr(), options_.depth);
  mapper_.Filter().Update(
      &map, StereoFrame{pair_frame.get(), pair.T_frame_ref, pair.gain, pair.offset, 0.0f});
  const float s = mapper_.Filter().NormalizeScale(&map);
  mapper_.SetMap(std::move(map));
  EndPairSearch();
  start_ = StartState::kConverging;  // pending_pair_ is the caller's to drop
  depth_updates_ = 1;
  lost_in_a_row_ = 0;
  // Normalisation multiplied inverse depths by s: lengths in keyframe units scale by 1/s.
  const SE3d T_kf_pair_frame(pair.T_frame_ref.Inverse().Rotation(),
                             pair.T_frame_ref.Inverse().Translation() / s);
  std::vector<RevisedPose> revised;
  auto buffered = std::move(initial_frames_);
  initial_frames_.clear();
  SE3d guess, previous;
  AffineBrightness affine;
  double last_time = std::numeric_limits<double>::quiet_NaN(), previous_time = last_time;
  for (const auto& [frame, unused] : buffered) {
    if (frame == pair_frame) guess = T_kf_pair_frame;
    const TrackingResult r = tracker_.TrackFrom(*mapper_.Reference(), *frame, guess, affine);
    std::optional<SE3d> pose;
    if (r.status != TrackingStatus::kLost) {
      previous = guess;
      guess = r.T_kf_frame;
      previous_time = std::exchange(last_time, frame->Timestamp());
      affine = r.affine;
      pose = r.T_kf_frame;
    }
    initial_frames_.emplace_back(frame, guess);
    revised.push_back(Revised(*frame, pose));
  }
  const double interval = last_time - previous_time;  // NaN unless two frames were tracked
  tracker_.SetState(MotionState{guess, previous.Inverse() * guess, affine,
                                static_cast<int>(buffered.size()), last_time,
                                interval > 0.0 ? interval : 0.0});
  return revised;
}

}  // namespace parallax
