#include "backend/system.hpp"

#include <chrono>
#include <cmath>

#include "core/check.hpp"

namespace parallax {
namespace {

std::vector<Eigen::Vector3f> WorldPoints(const InverseDepthMap& map, const Sim3d& S_w_kf) {
  std::vector<Eigen::Vector3f> points;
  const PinholeCamera& K = map.Keyframe().Camera(0);
  for (int y = 0; y < map.Height(); ++y) {
    for (int x = 0; x < map.Width(); ++x) {
      const std::size_t i = map.Index(x, y);
      if (!map.IsConfirmed(i)) continue;
      const Eigen::Vector3d p = K.Unproject(Eigen::Vector2d(x, y)) / map.idepth_smoothed[i];
      points.push_back((S_w_kf * p).cast<float>());
    }
  }
  return points;
}

}  // namespace

void SystemOptions::Check() const {
  pyramid.Check();
  reference.Check();
  tracker.Check();
  depth.Check();
  CheckOption(keyframe_distance > 0.0, "SystemOptions", "keyframe_distance", "must be > 0");
  CheckOption(min_keyframe_usage >= 0.0 && min_keyframe_usage <= 1.0, "SystemOptions",
              "min_keyframe_usage", "must be in [0, 1]");
  CheckOption(min_update_baseline >= 0.0, "SystemOptions", "min_update_baseline", "must be >= 0");
  CheckOption(min_frames_per_keyframe >= 1, "SystemOptions", "min_frames_per_keyframe",
              "must be >= 1");
}

System::System(const PinholeCamera& camera, const SystemOptions& options)
    : camera_(camera), options_(options), tracker_(options.tracker), depth_filter_(options.depth) {
  options_.Check();
}

void System::RebuildReference() {
  ImageF idepth, variance;
  map_->ExportSmoothed(&idepth, &variance);
  reference_ = std::make_unique<TrackingReference>(map_->KeyframePtr(), idepth, variance,
                                                   options_.reference);
}

void System::StartKeyframe(const std::shared_ptr<const Frame>& frame, const Sim3d& S_w_kf,
                           InverseDepthMap map) {
  if (map_) finished_points_.push_back(WorldPoints(*map_, S_w_kf_));
  map_ = std::make_unique<InverseDepthMap>(std::move(map));
  S_w_kf_ = S_w_kf;
  keyframes_.push_back({frame->Id(), frame->Timestamp(), S_w_kf});
  T_kf_last_ = SE3d();
  frames_in_keyframe_ = 0;
  RebuildReference();
}

std::vector<RevisedPose> System::FinishInitialisation() {
  std::vector<RevisedPose> revised;
  for (const auto& [frame, T_kf_frame] : initial_frames_) {
    const TrackingResult again = tracker_.Track(*reference_, *frame, {T_kf_frame}, affine_);
    if (again.status != TrackingStatus::kOk) continue;
    const Sim3d S_w_c = S_w_kf_ * Sim3d(again.T_kf_frame);
    revised.push_back(
        {frame->Id(), frame->Timestamp(), SE3d(S_w_c.Rotation(), S_w_c.Translation())});
  }
  initial_frames_.clear();
  initialised_at_frame_ = frame_count_ - 1;
  return revised;
}

void System::StartRandom(const std::shared_ptr<const Frame>& frame) {
  // LSD-style start: random inverse depth (mean 1) that the first frames refine.
  InverseDepthMap map(frame, options_.depth);
  map.InitializeRandom(1.0f);
  StartKeyframe(frame, Sim3d(), std::move(map));
}

FrameResult System::ProcessBeforeBootstrap(const std::shared_ptr<const Frame>& frame,
                                           const ImageU8& image) {
  FrameResult result;
  result.stats.reason = "initialising";
  const auto T_frame_kf = bootstrap_->TryFrame(image);
  if (!T_frame_kf) {
    bootstrap_frames_.push_back(frame);
    if (static_cast<int>(bootstrap_frames_.size()) >= options_.bootstrap_max_frames) {
      bootstrap_.reset();  // no usable pair: start over from random depth at this frame
      bootstrap_frames_.clear();
      StartRandom(frame);
      result.status = TrackingStatus::kOk;
      result.T_w_c = S_w_kf_.RigidPart();
      result.is_keyframe = true;
    }
    return result;
  }
  // Stereo with the bootstrap pose creates the keyframe's depth (full-range searches); then
  // the scale is normalised and the frames seen so far are tracked against it in order.
  depth_filter_.Update(map_.get(), StereoFrame{frame.get(), *T_frame_kf});
  const float s = depth_filter_.NormalizeScale(map_.get());
  RebuildReference();
  bootstrap_.reset();
  SE3d guess;
  for (const auto& buffered : bootstrap_frames_) {
    const TrackingResult r = tracker_.Track(*reference_, *buffered, {guess}, affine_);
    if (r.status == TrackingStatus::kLost) continue;
    guess = r.T_kf_frame;
    initial_frames_.emplace_back(buffered, r.T_kf_frame);
    const Sim3d S_w_c = S_w_kf_ * Sim3d(r.T_kf_frame);
    result.revised.push_back({buffered->Id(), buffered->Timestamp(), S_w_c.RigidPart()});
  }
  bootstrap_frames_.clear();
  // Normalisation multiplied inverse depths by s: lengths in keyframe units scale by 1/s.
  const SE3d T_kf_frame(T_frame_kf->Inverse().Rotation(), T_frame_kf->Inverse().Translation() / s);
  T_kf_last_ = T_kf_frame;
  result.status = TrackingStatus::kOk;
  result.stats.reason.clear();
  result.T_w_c = (S_w_kf_ * Sim3d(T_kf_frame)).RigidPart();
  initial_frames_.emplace_back(frame, T_kf_frame);
  return result;
}

FrameResult System::ProcessFrame(const ImageU8& image, double timestamp) {
  auto frame =
      std::make_shared<const Frame>(frame_count_++, timestamp, camera_, image, options_.pyramid);
  FrameResult result;
  if (!map_) {
    if (options_.initialization == Initialization::kTwoView) {
      // Keyframe with an empty map; its depth comes from the first good two-view pair.
      StartKeyframe(frame, Sim3d(), InverseDepthMap(frame, options_.depth));
      bootstrap_ = std::make_unique<TwoViewBootstrap>(camera_, options_.bootstrap);
      bootstrap_->SetReference(image);
    } else {
      StartRandom(frame);
    }
    result.status = TrackingStatus::kOk;
    result.T_w_c = SE3d();
    result.is_keyframe = true;
    return result;
  }
  if (bootstrap_) return ProcessBeforeBootstrap(frame, image);
  using Clock = std::chrono::steady_clock;
  const auto t0 = Clock::now();
  const TrackingResult tracked =
      tracker_.Track(*reference_, *frame, MotionHypotheses(T_kf_last_, T_prev_last_), affine_);
  const auto t1 = Clock::now();
  result.tracking_ms = std::chrono::duration<double, std::milli>(t1 - t0).count();
  result.status = tracked.status;
  result.stats = tracked.stats;
  if (tracked.status == TrackingStatus::kLost) return result;  // keep the last good state
  T_prev_last_ = T_kf_last_.Inverse() * tracked.T_kf_frame;
  T_kf_last_ = tracked.T_kf_frame;
  affine_ = tracked.affine;
  ++frames_in_keyframe_;
  const Sim3d S_w_c = S_w_kf_ * Sim3d(tracked.T_kf_frame);
  result.T_w_c = SE3d(S_w_c.Rotation(), S_w_c.Translation());
  // Distance relative to the mean depth (mean idepth is 1 after normalisation).
  const double relative_distance =
      tracked.T_kf_frame.Translation().norm() * map_->MeanSmoothedIdepth();
  const bool want_keyframe = frames_in_keyframe_ >= options_.min_frames_per_keyframe &&
                             (relative_distance > options_.keyframe_distance ||
                              tracked.stats.usage < options_.min_keyframe_usage ||
                              tracked.stats.good_ratio < options_.min_keyframe_good_ratio);
  if (tracked.status == TrackingStatus::kOk && relative_distance > options_.min_update_baseline) {
    const StereoFrame stereo{frame.get(), tracked.T_kf_frame.Inverse(), tracked.affine.Gain(),
                             tracked.affine.b, static_cast<float>(1.0 - tracked.stats.good_ratio)};
    depth_filter_.Update(map_.get(), stereo);
    ++depth_updates_;
    if (!want_keyframe) RebuildReference();
  }
  if (initialised_at_frame_ < 0) {
    initial_frames_.emplace_back(frame, tracked.T_kf_frame);
    if (depth_updates_ >= options_.initialization_updates || want_keyframe) {
      if (want_keyframe) RebuildReference();
      result.revised = FinishInitialisation();
    }
  }
  if (want_keyframe) {  // ok or poor: a degrading view is the reason to switch
    InverseDepthMap next = depth_filter_.Propagate(*map_, frame, tracked.T_kf_frame.Inverse(),
                                                   tracked.affine.Gain(), tracked.affine.b);
    const float s = depth_filter_.NormalizeScale(&next);
    // Normalising multiplies idepth by s, so a point's new-keyframe coordinates become
    // p' = p / s; the keyframe-to-world similarity absorbs it: S_w_new = S_w_c * Sim3(s).
    StartKeyframe(frame, S_w_c * Sim3d(s, SO3d(), Eigen::Vector3d::Zero()), std::move(next));
    affine_ = AffineBrightness{};
    T_prev_last_ = SE3d();
    result.is_keyframe = true;
  }
  result.mapping_ms = std::chrono::duration<double, std::milli>(Clock::now() - t1).count();
  return result;
}

std::vector<Eigen::Vector3f> System::MapPoints() const {
  std::vector<Eigen::Vector3f> all;
  for (const auto& points : finished_points_) all.insert(all.end(), points.begin(), points.end());
  if (map_) {
    const auto current = WorldPoints(*map_, S_w_kf_);
    all.insert(all.end(), current.begin(), current.end());
  }
  return all;
}

}  // namespace parallax
