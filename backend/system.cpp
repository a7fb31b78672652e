#include "backend/system.hpp"

#include <chrono>
#include <cmath>

#include "core/check.hpp"

namespace parallax {
namespace {

using Clock = std::chrono::steady_clock;

double MillisecondsSince(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

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
  update_direction.Check();
  bootstrap.Check();
  CheckOption(bootstrap_max_frames >= 1, "SystemOptions", "bootstrap_max_frames", "must be >= 1");
  CheckOption(auto_max_rotation_deg > 0.0, "SystemOptions", "auto_max_rotation_deg", "must be > 0");
  CheckOption(auto_max_direction_deg > 0.0, "SystemOptions", "auto_max_direction_deg",
              "must be > 0");
  CheckOption(auto_pair_residual_ratio > 0.0, "SystemOptions", "auto_pair_residual_ratio",
              "must be > 0");
  CheckOption(restart_after_lost >= 1, "SystemOptions", "restart_after_lost", "must be >= 1");
  CheckOption(keyframe_distance > 0.0, "SystemOptions", "keyframe_distance", "must be > 0");
  CheckOption(min_keyframe_usage >= 0.0 && min_keyframe_usage <= 1.0, "SystemOptions",
              "min_keyframe_usage", "must be in [0, 1]");
  CheckOption(min_update_baseline >= 0.0, "SystemOptions", "min_update_baseline", "must be >= 0");
  CheckOption(recent_keyframes >= 0, "SystemOptions", "recent_keyframes", "must be >= 0");
  CheckOption(min_start_texture >= 0.0 && min_start_texture < 1.0, "SystemOptions",
              "min_start_texture", "must be in [0, 1)");
  CheckOption(max_buffered_frames >= 1, "SystemOptions", "max_buffered_frames", "must be >= 1");
  CheckOption(min_frames_per_keyframe >= 1, "SystemOptions", "min_frames_per_keyframe",
              "must be >= 1");
  CheckOption(initialization_updates >= 1, "SystemOptions", "initialization_updates",
              "must be >= 1");
}

System::System(const PinholeCamera& camera, const SystemOptions& options)
    : camera_(camera),
      options_(options),
      tracker_(options.tracker),
      depth_filter_(options.depth),
      update_direction_(camera, options.update_direction) {
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
  if (map_) {
    finished_points_[map_->KeyframePtr()->Id()] = WorldPoints(*map_, S_w_kf_);
    if (options_.recent_keyframes > 0) {
      recent_.push_front({std::move(map_), std::move(reference_), S_w_kf_});
      if (static_cast<int>(recent_.size()) > options_.recent_keyframes) recent_.pop_back();
    }
  }
  map_ = std::make_unique<InverseDepthMap>(std::move(map));
  S_w_kf_ = S_w_kf;
  keyframes_.push_back({frame->Id(), frame->Timestamp(), S_w_kf});
  T_kf_last_ = SE3d();
  T_prev_last_ = SE3d();
  frames_in_keyframe_ = 0;
  RebuildReference();
}

FrameResult System::ProcessFrame(const ImageU8& image, double timestamp) {
  auto frame =
      std::make_shared<const Frame>(frame_count_++, timestamp, camera_, image, options_.pyramid);
  if (!map_) return StartFirstKeyframe(frame, image);
  if (options_.initialization == Initialization::kTwoView && bootstrap_) {
    return ProcessTwoViewOnly(frame, image);
  }
  FrameResult result;
  TrackingResult tracked = TrackFrame(*frame, &result);
  if (tracked.status == TrackingStatus::kLost && initialised_at_frame_ >= 0) {
    if (auto recovered = TrackRecentKeyframes(*frame)) {
      tracked = std::move(*recovered);
      result.status = tracked.status;
      result.stats = tracked.stats;
      result.stats.reason = "recovered on a recent keyframe";
      result.T_w_c = (S_w_kf_ * Sim3d(tracked.T_kf_frame)).RigidPart();
    }
  }
  if (initialised_at_frame_ < 0) {
    if (auto handled = ProcessWhileInitialising(frame, image, tracked)) return *handled;
  }
  if (tracked.status != TrackingStatus::kLost) MapFrame(frame, image, tracked, &result);
  return result;
}

TrackingResult System::TrackFrame(const Frame& frame, FrameResult* result) {
  const auto start = Clock::now();
  TrackingResult tracked =
      tracker_.Track(*reference_, frame, MotionHypotheses(T_kf_last_, T_prev_last_), affine_);
  result->tracking_ms = MillisecondsSince(start);
  result->status = tracked.status;
  result->stats = tracked.stats;
  if (tracked.status == TrackingStatus::kLost) return tracked;  // keep the last good state
  T_prev_last_ = T_kf_last_.Inverse() * tracked.T_kf_frame;
  T_kf_last_ = tracked.T_kf_frame;
  affine_ = tracked.affine;
  ++frames_in_keyframe_;
  result->T_w_c = (S_w_kf_ * Sim3d(tracked.T_kf_frame)).RigidPart();
  return tracked;
}

void System::MapFrame(const std::shared_ptr<const Frame>& frame, const ImageU8& image,
                      const TrackingResult& tracked, FrameResult* result) {
  const auto start = Clock::now();
  // Distance relative to the mean depth (mean idepth is 1 after normalisation).
  const double relative_distance =
      tracked.T_kf_frame.Translation().norm() * map_->MeanSmoothedIdepth();
  // While a two-view pair is sought or held the first keyframe stays: the random start it
  // would be compared with, or replaced by, lives in that keyframe.
  const bool start_pending = bootstrap_ || pending_pair_;
  const bool view_degrades = tracked.stats.usage < options_.min_keyframe_usage ||
                             tracked.stats.good_ratio < options_.min_keyframe_good_ratio;
  const bool want_keyframe = !start_pending &&
                             frames_in_keyframe_ >= options_.min_frames_per_keyframe &&
                             (view_degrades || relative_distance > options_.keyframe_distance);
  if (tracked.status == TrackingStatus::kOk && relative_distance > options_.min_update_baseline) {
    // Only once initialised: the start's keyframe and its selection stay as they were.
    const SE3d T_kf_update = initialised_at_frame_ < 0
                                 ? tracked.T_kf_frame
                                 : update_direction_.Refine(map_->KeyframePtr()->Id(), image,
                                                            tracked.T_kf_frame, relative_distance);
    const StereoFrame stereo{frame.get(), T_kf_update.Inverse(), tracked.affine.Gain(),
                             tracked.affine.b, static_cast<float>(1.0 - tracked.stats.good_ratio)};
    depth_filter_.Update(map_.get(), stereo);
    ++depth_updates_;
    if (!want_keyframe) RebuildReference();
  }
  if (initialised_at_frame_ < 0) {
    BufferInitialFrame(frame, tracked.T_kf_frame);
    if (depth_updates_ >= options_.initialization_updates || want_keyframe) {
      if (want_keyframe) RebuildReference();
      result->revised = FinishInitialisation();
    }
  }
  if (want_keyframe) {  // ok or poor: a degrading view is the reason to switch
    InverseDepthMap next = depth_filter_.Propagate(*map_, frame, tracked.T_kf_frame.Inverse(),
                                                   tracked.affine.Gain(), tracked.affine.b);
    const float s = depth_filter_.NormalizeScale(&next);
    // Normalising multiplies idepth by s, so a point's new-keyframe coordinates become
    // p' = p / s; the keyframe-to-world similarity absorbs it: S_w_new = S_w_c * Sim3(s).
    const Sim3d S_w_c = S_w_kf_ * Sim3d(tracked.T_kf_frame);
    const SE3d velocity(T_prev_last_.Rotation(), T_prev_last_.Translation() / s);
    StartKeyframe(frame, S_w_c * Sim3d(s, SO3d(), Eigen::Vector3d::Zero()), std::move(next));
    update_direction_.SetKeyframe(frame->Id(), image);
    T_prev_last_ = velocity;  // constant-velocity guess for the next frame, new keyframe units
    affine_ = AffineBrightness{};
    result->is_keyframe = true;
  }
  result->mapping_ms = MillisecondsSince(start);
}

std::optional<TrackingResult> System::TrackRecentKeyframes(const Frame& frame) {
  const Sim3d S_w_last = S_w_kf_ * Sim3d(T_kf_last_);
  for (auto it = recent_.begin(); it != recent_.end(); ++it) {
    // Two starts, each tracked on its own (the tracker would prefer a start that sees few
    // points with small residuals): the last pose carried over through the similarities,
    // and the keyframe's own pose (the camera came back to where it was taken).
    TrackingResult r = tracker_.Track(
        *it->reference, frame, {(it->S_w_kf.Inverse() * S_w_last).RigidPart()}, AffineBrightness{});
    if (r.status != TrackingStatus::kOk) {
      r = tracker_.Track(*it->reference, frame, {SE3d()}, AffineBrightness{});
    }
    if (r.status != TrackingStatus::kOk) continue;
    // The found keyframe becomes current again; the current one takes its place among the
    // recent ones (its points are finished; the found one's are live again).
    finished_points_[map_->KeyframePtr()->Id()] = WorldPoints(*map_, S_w_kf_);
    finished_points_.erase(it->map->KeyframePtr()->Id());
    std::swap(map_, it->map);
    std::swap(reference_, it->reference);
    std::swap(S_w_kf_, it->S_w_kf);
    std::rotate(recent_.begin(), it, std::next(it));
    update_direction_.Reset();  // its features are of the keyframe left behind
    T_kf_last_ = r.T_kf_frame;
    T_prev_last_ = SE3d();
    affine_ = r.affine;
    frames_in_keyframe_ = 1;
    return r;
  }
  return std::nullopt;
}

std::vector<Eigen::Vector3f> System::MapPoints() const {
  std::vector<Eigen::Vector3f> all;
  for (const auto& [id, points] : finished_points_)
    all.insert(all.end(), points.begin(), points.end());
  if (map_) {
    const auto current = WorldPoints(*map_, S_w_kf_);
    all.insert(all.end(), current.begin(), current.end());
  }
  return all;
}

}  // namespace parallax
