#include "backend/keyframe_graph.hpp"

#include <algorithm>

#include "depth/depth_map.hpp"

namespace parallax {

FrozenDepth FrozenDepth::FromMap(const InverseDepthMap& map) {
  FrozenDepth d;
  d.width = map.Width();
  d.height = map.Height();
  for (int y = 0; y < map.Height(); ++y) {
    for (int x = 0; x < map.Width(); ++x) {
      const std::size_t i = map.Index(x, y);
      if (!map.valid[i]) continue;
      d.pixel.push_back(y * map.Width() + x);
      d.idepth.push_back(map.idepth_smoothed[i]);
      d.variance.push_back(map.variance_smoothed[i]);
      d.confirmed.push_back(map.IsConfirmed(i) ? 1 : 0);
    }
  }
  return d;
}

void FrozenDepth::ToImages(ImageF* idepth_image, ImageF* variance_image) const {
  *idepth_image = ImageF(width, height, 0.0f);
  *variance_image = ImageF(width, height, 0.0f);
  for (std::size_t k = 0; k < pixel.size(); ++k) {
    idepth_image->Data()[pixel[k]] = idepth[k];
    variance_image->Data()[pixel[k]] = variance[k];
  }
}

std::size_t FrozenDepth::Bytes() const {
  return pixel.capacity() * sizeof(std::int32_t) + idepth.capacity() * sizeof(float) +
         variance.capacity() * sizeof(float) + confirmed.capacity();
}

void KeyframeGraph::Upsert(std::shared_ptr<const Keyframe> keyframe, const Sim3d& S_w_kf,
                           int map_id) {
  const std::int64_t id = keyframe->id;
  if (!Contains(id)) {
    const bool first_of_map = std::none_of(
        map_of_.begin(), map_of_.end(), [&](const auto& entry) { return entry.second == map_id; });
    poses_.SetVertex(id, S_w_kf, first_of_map);
    map_of_[id] = map_id;
  }
  keyframes_[id] = std::move(keyframe);
}

int KeyframeGraph::NumMaps() const {
  std::vector<int> maps;
  for (const auto& [id, map] : map_of_) {
    if (std::find(maps.begin(), maps.end(), map) == maps.end()) maps.push_back(map);
  }
  return static_cast<int>(maps.size());
}

void KeyframeGraph::MergeMaps(int from, int into, const Sim3d& S_into_from) {
  for (auto& [id, map] : map_of_) {
    if (map != from) continue;
    poses_.SetPose(id, S_into_from * poses_.Pose(id));
    poses_.SetFixed(id, false);
    map = into;
  }
}

void KeyframeGraph::AdoptOptimised(const KeyframeGraph& optimised, std::size_t edges_before) {
  // Corrections first, from the poses both graphs still share.
  std::map<int, std::int64_t> anchor;  // map -> its newest keyframe in the copy
  for (const auto& [id, map] : map_of_) {
    if (optimised.Contains(id)) anchor[map] = id;
  }
  for (auto& [id, map] : map_of_) {
    if (optimised.Contains(id)) continue;
    const auto a = anchor.find(map);
    if (a == anchor.end()) continue;  // a map started since: nothing moved it
    const Sim3d correction = optimised.Pose(a->second) * Pose(a->second).Inverse();
    poses_.SetPose(id, correction * Pose(id));
    if (optimised.MapOf(a->second) != map) poses_.SetFixed(id, false);  // merged away
    map = optimised.MapOf(a->second);
  }
  for (auto& [id, map] : map_of_) {
    if (!optimised.Contains(id)) continue;
    poses_.SetVertex(id, optimised.Pose(id), optimised.Poses().IsFixed(id));
    map = optimised.MapOf(id);
  }
  const std::vector<PoseGraphEdge>& edges = optimised.Poses().Edges();
  for (std::size_t k = edges_before; k < edges.size(); ++k) {
    if (Contains(edges[k].i) && Contains(edges[k].j)) poses_.AddEdge(edges[k]);
  }
}

bool KeyframeGraph::HasEdge(std::int64_t a, std::int64_t b) const {
  return std::any_of(poses_.Edges().begin(), poses_.Edges().end(), [&](const PoseGraphEdge& e) {
    return (e.i == a && e.j == b) || (e.i == b && e.j == a);
  });
}

EdgeCounts KeyframeGraph::CountEdges() const {
  EdgeCounts c;
  for (const PoseGraphEdge& e : poses_.Edges()) {
    c.odometry += e.kind == EdgeKind::kOdometry;
    c.neighbour += e.kind == EdgeKind::kNeighbour;
    c.loop += e.kind == EdgeKind::kLoop;
  }
  return c;
}

std::shared_ptr<const Keyframe> Materialize(const std::shared_ptr<const Keyframe>& keyframe,
                                            const PinholeCamera& camera,
                                            const PyramidOptions& pyramid,
                                            const TrackingReferenceOptions& reference) {
  if (!keyframe->IsCompact()) return keyframe;
  auto full = std::make_shared<Keyframe>(*keyframe);
  full->frame = std::make_shared<const Frame>(keyframe->id, keyframe->timestamp, camera,
                                              keyframe->image, pyramid);
  ImageF idepth, variance;
  keyframe->depth.ToImages(&idepth, &variance);
  full->reference =
      std::make_shared<const TrackingReference>(full->frame, idepth, variance, reference);
  return full;
}

void KeyframeGraph::Compact(const std::vector<std::int64_t>& keep) {
  for (auto& [id, kf] : keyframes_) {
    if (kf->IsCompact() || std::find(keep.begin(), keep.end(), id) != keep.end()) continue;
    auto compact = std::make_shared<Keyframe>(*kf);
    compact->frame.reset();
    compact->reference.reset();
    kf = std::move(compact);
  }
}

std::vector<Eigen::Vector3f> KeyframeGraph::MapPoints(const PinholeCamera& camera) const {
  std::vector<Eigen::Vector3f> points;
  ForEachMapPoint(camera, [&](const MapPoint& p) { points.push_back(p.p_w); });
  return points;
}

void KeyframeGraph::ForEachMapPoint(const PinholeCamera& camera,
                                    const std::function<void(const MapPoint&)>& fn) const {
  for (const auto& [id, kf] : keyframes_) {
    const Sim3d& S_w_kf = Pose(id);
    const PinholeCamera& K = camera;
    const FrozenDepth& d = kf->depth;
    for (std::size_t k = 0; k < d.Size(); ++k) {
      if (!d.confirmed[k]) continue;
      const Eigen::Vector2d px(d.pixel[k] % d.width, d.pixel[k] / d.width);
      const Eigen::Vector3d p = K.Unproject(px) / d.idepth[k];
      fn(MapPoint{(S_w_kf * p).cast<float>(),
                  kf->image.Data()[static_cast<std::size_t>(d.pixel[k])]});
    }
  }
}

std::size_t KeyframeGraph::Bytes() const {
  std::size_t bytes = 0;
  for (const auto& [id, kf] : keyframes_) {
    bytes += kf->depth.Bytes() + sizeof(Keyframe) + kf->image.NumPixels();
    if (!kf->frame) continue;
    const ImagePyramid& pyramid = kf->frame->Pyramid();
    for (int l = 0; l < pyramid.NumLevels(); ++l) {
      const PyramidLevel& level = pyramid.Level(l);
      // intensity, dx, dy
      bytes += static_cast<std::size_t>(level.Width() * level.Height()) * sizeof(float) * 3;
    }
    if (kf->reference) {
      for (int l = 0; l < kf->reference->NumLevels(); ++l) {
        bytes += kf->reference->Level(l).Size() * 7 * sizeof(float);
      }
    }
  }
  return bytes;
}

void KeyframeGraph::Clear() {
  keyframes_.clear();
  map_of_.clear();
  poses_ = PoseGraph();
}

}  // namespace parallax
