// System: choosing between the random start and the two-view start when their geometry
// agrees (docs/configuration.md, "Choosing the initialisation").

#include <optional>
#include <utility>

#include "backend/system.hpp"

namespace parallax {
namespace {

/// Residual charged for a buffered frame the map cannot track (grey levels; well above any
/// tracked frame's RMS residual).
constexpr double kLostFrameResidual = 100.0;

}  // namespace

/// Everything the start has built that trying another start would overwrite.
struct System::StartSnapshot {
  std::unique_ptr<InverseDepthMap> map;
  std::shared_ptr<const TrackingReference> reference;  // immutable: shared, not copied
  std::vector<std::pair<std::shared_ptr<const Frame>, SE3d>> frames;
  MotionState motion;
  int depth_updates = 0;
};

System::StartSnapshot System::SaveStart() const {
  StartSnapshot s;
  s.map = std::make_unique<InverseDepthMap>(mapper_.Map());
  s.reference = mapper_.Reference();
  s.frames = initial_frames_;
  s.motion = tracker_.State();
  s.depth_updates = depth_updates_;
  return s;
}

void System::RestoreStart(StartSnapshot snapshot) {
  mapper_.Restore(std::move(snapshot.map), std::move(snapshot.reference));
  initial_frames_ = std::move(snapshot.frames);
  tracker_.SetState(snapshot.motion);
  depth_updates_ = snapshot.depth_updates;
}

double System::BufferedResidual(BufferedPoses* poses) {
  poses->clear();
  if (initial_frames_.empty()) return 0.0;
  double sum = 0.0;
  AffineBrightness affine;  // carried along: exposure changes smoothly between frames
  for (const auto& [frame, T_kf_frame] : initial_frames_) {
    const TrackingResult r = tracker_.TrackFrom(*mapper_.Reference(), *frame, T_kf_frame, affine);
    if (r.status == TrackingStatus::kLost) {
      sum += kLostFrameResidual;
      poses->emplace_back();
      continue;
    }
    affine = r.affine;
    sum += r.stats.residual_rms;
    poses->emplace_back(r.T_kf_frame);
  }
  return sum / static_cast<double>(initial_frames_.size());
}

void System::RefineWithBufferedFrames() {
  AffineBrightness affine;
  const std::size_t n = initial_frames_.size();
  for (std::size_t i = 0; i < n; ++i) {
    if (!options_.PairRefinesWith(i, n)) continue;
    auto& [frame, T_kf_frame] = initial_frames_[i];
    const TrackingResult r = tracker_.TrackFrom(*mapper_.Reference(), *frame, T_kf_frame, affine);
    if (r.status != TrackingStatus::kOk) continue;
    affine = r.affine;
    T_kf_frame = r.T_kf_frame;
    const double baseline = r.T_kf_frame.Translation().norm() * mapper_.Map().MeanSmoothedIdepth();
    if (baseline <= options_.min_update_baseline) continue;
    mapper_.Update(*frame, r.T_kf_frame, r);
    mapper_.PublishReference();
  }
}

System::BufferedPoses System::KeepTheBetterStart(const std::shared_ptr<const Frame>& pair_frame,
                                                 const TwoViewPair& pair) {
  // The pair's start, refined by the buffered frames, is kept (docs/configuration.md). With
  // auto_pair_residual_ratio > 0 it must also explain the frames with a clearly lower
  // residual than the random start, which is saved first and restored otherwise.
  const bool compare = options_.auto_pair_residual_ratio > 0.0;
  BufferedPoses random_poses, pair_poses;
  double random_residual = 0.0;
  std::optional<StartSnapshot> random_start;
  if (compare) {
    random_residual = BufferedResidual(&random_poses);
    random_start = SaveStart();
  }
  StartFromPair(pair_frame, pair);
  RefineWithBufferedFrames();
  const double pair_residual = BufferedResidual(&pair_poses);
  // Near-equal residuals are no evidence against the random start, whose depth has seen the
  // frames live: the pair must be clearly better.
  if (compare && !(pair_residual < options_.auto_pair_residual_ratio * random_residual)) {
    RestoreStart(std::move(*random_start));
    return random_poses;
  }
  return pair_poses;
}

}  // namespace parallax
