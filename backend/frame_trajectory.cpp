#include "backend/frame_trajectory.hpp"

namespace parallax {
namespace {

/// The correction to spread over a run of frames anchored to keyframe `a` (frames
/// [first, end) of `frames`), and the frame ids where it starts (0) and is whole (1).
struct Spread {
  Sim3d::Tangent xi = Sim3d::Tangent::Zero();
  double start = 0.0;
  double whole = 1.0;
};

std::optional<Spread> CorrectionTowardsSuccessor(const FrameAnchors& frames, std::int64_t a,
                                                 const Sim3d& S_w_a, std::size_t first,
                                                 std::size_t end) {
  const auto& anchors = *frames.anchors;
  // The frame after the run must be the successor keyframe's own, grown from `a`.
  if (end >= anchors.size() || !anchors[end]) return std::nullopt;
  const std::int64_t b = anchors[end]->keyframe_id;
  if (b != frames.first_frame_id + static_cast<std::int64_t>(end)) return std::nullopt;
  const auto tracked = frames.tracked->find(b);
  if (tracked == frames.tracked->end() || tracked->second.parent != a) return std::nullopt;
  const std::optional<Sim3d> S_w_b = frames.keyframe_pose(b);
  if (!S_w_b) return std::nullopt;
  // B's tracked pose must continue the run's motion: a step to it that departs from the step
  // before by more than that step's length is B's own tracking error, which the graph
  // corrected for B alone (the frames before it were not tracked that way).
  if (end - first >= 2) {
    const Eigen::Vector3d last = anchors[end - 1]->T_kf_frame.Translation();
    const Eigen::Vector3d step_before = last - anchors[end - 2]->T_kf_frame.Translation();
    const Eigen::Vector3d step_to_b = tracked->second.S_parent_kf.Translation() - last;
    if ((step_to_b - step_before).norm() > frames.max_step_change * step_before.norm()) {
      return std::nullopt;
    }
  }
  const Sim3d correction = S_w_a.Inverse() * *S_w_b * tracked->second.S_parent_kf.Inverse();
  Spread spread;
  spread.xi = correction.Log();
  if (!spread.xi.allFinite()) return std::nullopt;
  // The run starts at the keyframe's own frame, or (a keyframe returned to) after the frame
  // before it, which was tracked elsewhere.
  const std::int64_t first_id = frames.first_frame_id + static_cast<std::int64_t>(first);
  spread.start = static_cast<double>(first_id == a ? first_id : first_id - 1);
  spread.whole = static_cast<double>(b);
  return spread;
}

}  // namespace

std::vector<FramePose> FrameWorldPoses(const FrameAnchors& frames, bool spread) {
  const auto& anchors = *frames.anchors;
  std::vector<FramePose> poses;
  std::size_t first = 0;
  while (first < anchors.size()) {
    if (!anchors[first]) {
      ++first;
      continue;
    }
    // A run of consecutive frames anchored to the same keyframe.
    const std::int64_t a = anchors[first]->keyframe_id;
    std::size_t end = first;
    while (end < anchors.size() && anchors[end] && anchors[end]->keyframe_id == a) ++end;
    if (const std::optional<Sim3d> S_w_a = frames.keyframe_pose(a)) {
      const std::optional<Spread> correction =
          spread ? CorrectionTowardsSuccessor(frames, a, *S_w_a, first, end) : std::nullopt;
      for (std::size_t k = first; k < end; ++k) {
        const std::int64_t id = frames.first_frame_id + static_cast<std::int64_t>(k);
        const Sim3d S_a_frame(anchors[k]->T_kf_frame);
        if (!correction) {
          poses.push_back({id, 0.0, (*S_w_a * S_a_frame).RigidPart()});
          continue;
        }
        const double alpha =
            (static_cast<double>(id) - correction->start) / (correction->whole - correction->start);
        poses.push_back(
            {id, 0.0, (*S_w_a * Sim3d::Exp(alpha * correction->xi) * S_a_frame).RigidPart()});
      }
    }
    first = end;
  }
  return poses;
}

}  // namespace parallax
