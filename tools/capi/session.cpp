#include "tools/capi/session.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>

namespace parallax::capi {
namespace {

px_event_type EventType(SystemEvent::Kind kind, bool* wanted) {
  *wanted = true;
  switch (kind) {
    case SystemEvent::Kind::kKeyframeCreated:
      return PX_EVENT_KEYFRAME;
    case SystemEvent::Kind::kLoopClosed:
      return PX_EVENT_LOOP_CLOSED;
    case SystemEvent::Kind::kLost:
      return PX_EVENT_LOST;
    case SystemEvent::Kind::kRelocalised:
      return PX_EVENT_RELOCALIZED;
    case SystemEvent::Kind::kGraphOptimised:
      return PX_EVENT_MAP_OPTIMIZED;
    case SystemEvent::Kind::kNewMap:
      return PX_EVENT_NEW_MAP;
    case SystemEvent::Kind::kMapsMerged:
      return PX_EVENT_MAPS_MERGED;
    case SystemEvent::Kind::kPosesRevised:
      return PX_EVENT_POSES_REVISED;
    case SystemEvent::Kind::kRecovered:
      return PX_EVENT_RECOVERED;
    case SystemEvent::Kind::kRestarted:
      return PX_EVENT_RESTARTED;
    case SystemEvent::Kind::kDiverged:
      return PX_EVENT_DIVERGED;
    case SystemEvent::Kind::kKeyframeFinished:
      break;  // internal bookkeeping
  }
  *wanted = false;
  return PX_EVENT_KEYFRAME;
}

void Require(bool condition, const std::string& message) {
  if (!condition) throw StatusError(PX_ERROR_INVALID_ARGUMENT, message);
}

}  // namespace

void ToRowMajor(const SE3d& T, double out[16]) {
  const Eigen::Matrix3d R = T.Rotation().Matrix();
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) out[4 * r + c] = R(r, c);
    out[4 * r + 3] = T.Translation()[r];
  }
  out[12] = out[13] = out[14] = 0.0;
  out[15] = 1.0;
}

Session::Session(const Camera& camera, const SessionOptions& options)
    : options_(options), undistorter_(camera, options.rectification) {
  system_ = std::make_unique<System>(undistorter_.OutputCamera(), options_.system);
}

void Session::RequireUsable() const {
  if (!failure_.empty()) {
    throw StatusError(PX_ERROR_INVALID_STATE, "the system failed on an earlier frame (" + failure_ +
                                                  "); call px_system_reset or px_system_load_map");
  }
}

px_frame_result Session::ProcessFrame(const std::uint8_t* gray, int width, int height,
                                      int stride_bytes, double timestamp_s) {
  RequireUsable();
  const Camera& camera = undistorter_.InputCamera();
  Require(gray != nullptr, "gray is NULL");
  Require(width == camera.Width() && height == camera.Height(),
          "the image is " + std::to_string(width) + "x" + std::to_string(height) + ", the camera " +
              std::to_string(camera.Width()) + "x" + std::to_string(camera.Height()));
  Require(stride_bytes >= width, "stride_bytes " + std::to_string(stride_bytes) +
                                     " is less than the width " + std::to_string(width));
  Require(std::isfinite(timestamp_s), "timestamp_s is not finite");
  Require(!last_timestamp_ || timestamp_s > *last_timestamp_,
          "timestamp_s " + std::to_string(timestamp_s) + " is not after the previous frame's " +
              std::to_string(last_timestamp_.value_or(0.0)));
  if (input_.Width() != width || input_.Height() != height) input_ = ImageU8(width, height);
  for (int y = 0; y < height; ++y) {
    std::memcpy(input_.Row(y), gray + static_cast<std::ptrdiff_t>(y) * stride_bytes,
                static_cast<std::size_t>(width));
  }
  FrameResult result;
  try {
    undistorter_.Apply(input_, &rectified_);
    result = system_->ProcessFrame(rectified_, timestamp_s);
  } catch (const std::exception& e) {
    failure_ = e.what();
    throw;
  }
  last_timestamp_ = timestamp_s;
  QueueEvents(result);
  px_frame_result out{};
  out.state = StateOf(result);
  out.has_pose = result.T_w_c ? 1 : 0;
  ToRowMajor(result.T_w_c.value_or(SE3d()), out.T_w_c);
  out.is_keyframe = result.is_keyframe ? 1 : 0;
  out.frame_id = system_->NextFrameId() - 1;
  return out;
}

px_tracking_state Session::StateOf(const FrameResult& result) const {
  if (!result.T_w_c) return result.initialising ? PX_STATE_INITIALIZING : PX_STATE_LOST;
  const bool relocalised =
      std::any_of(result.events.begin(), result.events.end(),
                  [](const SystemEvent& e) { return e.kind == SystemEvent::Kind::kRelocalised; });
  if (relocalised) return PX_STATE_RELOCALIZED;
  if (result.initialising) return PX_STATE_INITIALIZING;
  return result.status == TrackingStatus::kOk ? PX_STATE_TRACKING : PX_STATE_POOR;
}

void Session::QueueEvents(const FrameResult& result) {
  for (const SystemEvent& e : result.events) {
    bool wanted = false;
    const px_event_type type = EventType(e.kind, &wanted);
    if (!wanted) continue;
    if (events_.size() >= options_.max_events) {
      events_.pop_front();
      ++events_dropped_;
    }
    events_.push_back(px_event{type, e.frame_id, e.keyframe_id, e.loop_keyframe_id, e.map_id});
  }
}

std::optional<px_event> Session::PollEvent(std::uint64_t* dropped) {
  *dropped = events_dropped_;
  events_dropped_ = 0;
  if (events_.empty()) return std::nullopt;
  const px_event e = events_.front();
  events_.pop_front();
  return e;
}

std::vector<float> Session::MapPoints() const {
  RequireUsable();
  std::vector<float> xyz;
  system_->ForEachMapPoint([&](const MapPoint& p) {
    xyz.insert(xyz.end(), {p.p_w.x(), p.p_w.y(), p.p_w.z()});
  });
  return xyz;
}

std::vector<px_keyframe> Session::Keyframes() const {
  RequireUsable();
  std::vector<px_keyframe> out;
  for (const KeyframeRecord& kf : system_->Keyframes()) {
    px_keyframe k{};
    k.id = kf.frame_id;
    k.timestamp_s = kf.timestamp;
    ToRowMajor(SE3d(kf.S_w_kf.Rotation(), kf.S_w_kf.Translation()), k.T_w_kf);
    k.scale = kf.S_w_kf.Scale();
    k.map_id = kf.map_id;
    out.push_back(k);
  }
  return out;
}

std::optional<SE3d> Session::FramePose(std::int64_t frame_id) const {
  RequireUsable();
  const std::vector<parallax::FramePose> poses = system_->Trajectory();
  const auto it = std::lower_bound(
      poses.begin(), poses.end(), frame_id,
      [](const parallax::FramePose& p, std::int64_t id) { return p.frame_id < id; });
  if (it == poses.end() || it->frame_id != frame_id) return std::nullopt;
  return it->T_w_c;
}

void Session::FinishMapping() {
  RequireUsable();
  FrameResult finished;
  try {
    finished.events = system_->FinishMapping();
  } catch (const std::exception& e) {
    failure_ = e.what();
    throw;
  }
  QueueEvents(finished);
}

void Session::SaveMap(const std::string& path) const {
  RequireUsable();
  try {
    system_->SaveMap(path);
  } catch (const std::logic_error& e) {
    throw StatusError(PX_ERROR_INVALID_STATE, e.what());
  }
}

void Session::LoadMap(const std::string& path) {
  auto loaded = std::make_unique<System>(undistorter_.OutputCamera(), options_.system);
  loaded->LoadMap(path);
  system_ = std::move(loaded);
  last_timestamp_.reset();
  failure_.clear();
  events_.clear();
  events_dropped_ = 0;
}

void Session::Reset() {
  system_ = std::make_unique<System>(undistorter_.OutputCamera(), options_.system);
  last_timestamp_.reset();
  failure_.clear();
  events_.clear();
  events_dropped_ = 0;
}

}  // namespace parallax::capi
