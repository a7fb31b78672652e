// System: saving and loading maps, and tracking on a loaded map until it is relocalised
// (docs/map_files.md).

#include <cmath>
#include <stdexcept>

#include "backend/map_file.hpp"
#include "backend/system.hpp"
#include "core/binary_file.hpp"

namespace parallax {
namespace {

bool SameCamera(const PinholeCamera& a, const PinholeCamera& b) {
  constexpr double kTolerance = 1e-9;
  return a.Width() == b.Width() && a.Height() == b.Height() &&
         std::abs(a.Fx() - b.Fx()) <= kTolerance * b.Fx() &&
         std::abs(a.Fy() - b.Fy()) <= kTolerance * b.Fy() &&
         std::abs(a.Cx() - b.Cx()) <= kTolerance * b.Fx() &&
         std::abs(a.Cy() - b.Cy()) <= kTolerance * b.Fy();
}

std::string CameraText(const PinholeCamera& c) {
  return std::to_string(c.Width()) + "x" + std::to_string(c.Height()) +
         " fx=" + std::to_string(c.Fx()) + " fy=" + std::to_string(c.Fy()) +
         " cx=" + std::to_string(c.Cx()) + " cy=" + std::to_string(c.Cy());
}

}  // namespace

std::vector<std::uint8_t> System::EncodeMapBytes() const {
  const std::lock_guard<std::mutex> lock(engine_mutex_);
  return EncodeMapBytesLocked();
}

std::vector<std::uint8_t> System::EncodeMapBytesLocked() const {
  if (start_ != StartState::kInitialised) {
    throw std::logic_error(start_ == StartState::kRelocalising
                               ? "no map to save: the loaded map has not been relocalised yet"
                               : "no map to save: the first keyframe is still initialising");
  }
  // A copy of the graph (keyframes are shared, immutable) with the unfinished current
  // keyframe added as it stands, so that saving changes nothing in the running system.
  KeyframeGraph graph = graph_;
  // Real-time mode: keyframes the backend has not linked yet get their tracking chain.
  AddChainEdges(&graph, backend_running_);
  AddChainEdges(&graph, backend_pending_);
  if (mapper_.HasMap() && !graph.Contains(current_.id)) {
    graph.Upsert(mapper_.Freeze(), CurrentKeyframePose(), current_map_);
    AddChainEdges(&graph, {FinishedKeyframe{current_.id, current_.parent, current_.S_parent_kf}});
  }
  // Keyframes described only here (place recognition off, or the current one) keep their
  // entries alive until the map is encoded.
  const std::shared_lock<std::shared_mutex> place(place_mutex_);
  std::vector<std::shared_ptr<const PlaceEntry>> described;
  std::map<std::int64_t, const OrbFeatures*> features;
  for (const std::int64_t id : graph.Ids()) {
    if (place_.Contains(id)) {
      features[id] = &place_.Entry(id).features;
    } else {
      described.push_back(place_.Describe(graph.Get(id).image));
      features[id] = &described.back()->features;
    }
  }
  return EncodeMap(camera_, graph, features, frame_count_, next_map_);
}

void System::SaveMap(const std::string& path) const { WriteMapFile(path, EncodeMapBytes()); }

void System::LoadMap(const std::string& path) {
  if (frame_count_ != first_frame_id_) {
    throw std::logic_error("a map can only be loaded before the first frame");
  }
  std::vector<std::uint8_t> bytes;
  try {
    bytes = ReadBinaryFile(path);
  } catch (const std::runtime_error& e) {
    throw MapFileError(e.what());
  }
  LoadMapBytes(bytes, path);
}

void System::LoadMapBytes(std::span<const std::uint8_t> bytes, const std::string& source) {
  const std::lock_guard<std::mutex> lock(engine_mutex_);
  if (frame_count_ != first_frame_id_) {
    throw std::logic_error("a map can only be loaded before the first frame");
  }
  MapContents contents = DecodeMap(bytes, source);
  if (!SameCamera(contents.camera, camera_)) {
    throw MapFileError(source + ": the map was made with the camera " +
                       CameraText(contents.camera) + ", this system has " + CameraText(camera_));
  }
  // Everything is decoded and checked: from here on nothing throws but allocation.
  graph_ = std::move(contents.graph);
  const std::unique_lock<std::shared_mutex> place(place_mutex_);
  place_.Clear();
  loop_closer_.Clear();
  for (auto& [id, features] : contents.features)
    place_.Add(id, place_.Describe(std::move(features)));
  mapper_.Clear();
  current_ = CurrentKeyframe{};
  frame_count_ = first_frame_id_ = contents.next_frame_id;
  next_map_ = contents.next_map_id;
  current_map_ = next_map_;  // none until relocalised; never 0 (ClearMap keeps the maps)
  start_ = StartState::kRelocalising;
}

FrameResult System::ProcessOnLoadedMap(const std::shared_ptr<const Frame>& frame,
                                       const ImageU8& image) {
  if (frame->Id() == first_frame_id_) last_posed_timestamp_ = frame->Timestamp();
  FrameResult result;
  auto relocalised = Relocalise(*frame, image);
  if (!relocalised) {
    if (frame->Timestamp() - last_posed_timestamp_ >= options_.new_map_after_lost_s) {
      return StartNewMap(frame, image);
    }
    result.stats.reason = "not relocalised on the loaded map";
    return result;
  }
  TrackingResult tracked = std::move(relocalised->second);
  result.status = tracked.status;
  result.stats = tracked.stats;
  result.stats.reason = "relocalised";
  ReturnToKeyframe(relocalised->first, &result);
  start_ = StartState::kInitialised;
  initialised_at_frame_ = static_cast<int>(frame->Id() - first_frame_id_);
  tracker_.StartKeyframe();
  tracker_.SetState(MotionState{tracked.T_kf_frame, SE3d(), tracked.affine, 1});
  SetPose(&result, tracked.T_kf_frame);
  result.events.push_back({SystemEvent::Kind::kRelocalised, frame->Id(), current_.id});
  MapFrame(frame, image, tracked, &result);
  return result;
}

}  // namespace parallax
