#pragma once
// World poses of the frames from the keyframe graph, with the graph's correction of each
// keyframe spread over the frames tracked towards it (docs/math/pose_graph.md, "Frames
// between keyframes").

#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <vector>

#include "backend/system_results.hpp"
#include "core/se3.hpp"
#include "core/sim3.hpp"

namespace parallax {

/// How a keyframe was placed when it was created: relative to the keyframe it grew from, as
/// tracking measured it (before any optimisation).
struct TrackedKeyframe {
  std::int64_t parent = 0;
  Sim3d S_parent_kf;
};

/// The frames' anchors, in frame order, and what the graph knows of their keyframes.
struct FrameAnchors {
  /// Index k holds frame first_frame_id + k.
  const std::vector<std::optional<AnchoredPose>>* anchors = nullptr;
  std::int64_t first_frame_id = 0;
  /// Keyframe id -> keyframe-to-world pose now, or nothing when the keyframe is no longer
  /// in the map (a restart withdrew it): its frames have no pose then.
  std::function<std::optional<Sim3d>(std::int64_t)> keyframe_pose;
  /// Keyframe id -> how it was placed when created (absent: the first keyframe of a map).
  const std::map<std::int64_t, TrackedKeyframe>* tracked = nullptr;
  /// No spreading towards a keyframe whose tracked step from the run's last frame differs
  /// from the step before it by more than this times that step's length.
  double max_step_change = 1.0;
};

/// World pose (camera-to-world) of every frame that has one, in frame order (FramePose's
/// timestamp left 0). A frame anchored to keyframe A is S_w_A * T_A_frame. With `spread`,
/// the frames tracked against A just before its successor B was created (B grew from A)
/// follow B's correction in part: B was placed by the same tracking against A's depth, and
/// the graph's correction D = S_A_B(now) * S_A_B(tracked)^-1 is applied to the frame as
/// Exp(alpha Log D), alpha growing linearly from 0 at the start of the run of frames to 1
/// at B. Without it a graph correction of B shows as a step between the last frame of A and
/// B itself. Not spread: across a frame without a pose, towards a keyframe that grew from
/// another, or when B's tracked step breaks the run's motion (`max_step_change`).
std::vector<FramePose> FrameWorldPoses(const FrameAnchors& frames, bool spread);

}  // namespace parallax
