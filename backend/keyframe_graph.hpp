#pragma once
// The map: every finished keyframe with its frozen semi-dense depth (keyframe coordinates),
// its pose S_w_kf (held once, in the pose graph) and the edges between keyframes
// (docs/architecture.md, "Keyframe graph").

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <vector>

#include "backend/pose_graph.hpp"
#include "core/frame.hpp"
#include "core/image.hpp"
#include "tracking/tracking_reference.hpp"

namespace parallax {

class InverseDepthMap;

/// Semi-dense inverse depth of a finished keyframe, stored sparsely (structure of arrays):
/// pixel index y * width + x, smoothed inverse depth (1/keyframe unit), its variance, and
/// whether stereo confirmed it (random and hole-filled hypotheses are not exported as map
/// points but still help tracking).
struct FrozenDepth {
  int width = 0;
  int height = 0;
  std::vector<std::int32_t> pixel;
  std::vector<float> idepth;
  std::vector<float> variance;
  std::vector<std::uint8_t> confirmed;

  /// The valid pixels of `map` (smoothed estimates).
  static FrozenDepth FromMap(const InverseDepthMap& map);
  /// Keyframe-sized images (0 where no estimate), e.g. for a TrackingReference.
  void ToImages(ImageF* idepth_image, ImageF* variance_image) const;
  std::size_t Size() const { return pixel.size(); }
  std::size_t Bytes() const;
};

/// A finished keyframe. Immutable once in the graph, except that a keyframe the tracker
/// returned to and refined again is replaced as a whole, and that old keyframes are
/// compacted: their frame pyramid and tracking reference (~10 MB at 640x480) are dropped and
/// rebuilt from `image` and `depth` when a later stage needs them (Materialize).
struct Keyframe {
  std::int64_t id = 0;  ///< the id of its frame
  double timestamp = 0.0;
  ImageU8 image;  ///< the undistorted 8-bit image (pyramid level 0)
  FrozenDepth depth;
  std::shared_ptr<const Frame> frame;                  ///< null when compacted
  std::shared_ptr<const TrackingReference> reference;  ///< null when compacted

  bool IsCompact() const { return !frame || !reference; }
};

/// The keyframe with its frame and tracking reference rebuilt if it was compacted (the same
/// data as before compaction: Frame and TrackingReference are deterministic functions of the
/// image and the depth).
std::shared_ptr<const Keyframe> Materialize(const std::shared_ptr<const Keyframe>& keyframe,
                                            const PinholeCamera& camera,
                                            const PyramidOptions& pyramid,
                                            const TrackingReferenceOptions& reference);

/// A confirmed semi-dense point in the world, with the grey level of its keyframe pixel.
struct MapPoint {
  Eigen::Vector3f p_w;
  std::uint8_t intensity = 0;
};

/// Counts by edge kind.
struct EdgeCounts {
  int odometry = 0;
  int neighbour = 0;
  int loop = 0;
};

/// Owns the finished keyframes and the Sim(3) pose graph over them.
class KeyframeGraph {
 public:
  /// Adds a finished keyframe of map `map_id` at pose S_w_kf (in that map's world), or
  /// replaces the data of one already in the graph (its optimised pose and map are kept;
  /// S_w_kf and map_id are then ignored). The first keyframe of a map is its gauge (fixed
  /// in optimisation) until the map is merged into another.
  void Upsert(std::shared_ptr<const Keyframe> keyframe, const Sim3d& S_w_kf, int map_id = 0);
  /// The map (connected component, with its own world frame) keyframe `id` belongs to.
  int MapOf(std::int64_t id) const { return map_of_.at(id); }
  /// Distinct maps with at least one keyframe.
  int NumMaps() const;
  /// Moves every keyframe of map `from` into map `into`: S_w_k <- S_into_from * S_w_k; its
  /// gauge is released (the merged graph keeps `into`'s).
  void MergeMaps(int from, int into, const Sim3d& S_into_from);
  /// Takes the backend's result from `optimised`, a copy of this graph made when the
  /// backend started (real-time mode: the mapping thread went on meanwhile). Keyframes in
  /// both get its poses, gauges and maps; keyframes added since move with the newest
  /// keyframe of their map in the copy (its correction applied to them, its map taken);
  /// its edges from index `edges_before` on are added. The keyframe data stays this
  /// graph's (a keyframe may have been compacted or replaced since).
  void AdoptOptimised(const KeyframeGraph& optimised, std::size_t edges_before);
  bool Contains(std::int64_t id) const { return keyframes_.count(id) > 0; }
  /// Throws std::out_of_range for an unknown id.
  const Keyframe& Get(std::int64_t id) const { return *keyframes_.at(id); }
  const std::shared_ptr<const Keyframe>& GetPtr(std::int64_t id) const { return keyframes_.at(id); }
  /// Keyframe-to-world similarity (scale: the keyframe's normalised depth unit).
  const Sim3d& Pose(std::int64_t id) const { return poses_.Pose(id); }
  /// Ids in ascending order (frame order).
  std::vector<std::int64_t> Ids() const { return poses_.VertexIds(); }
  std::size_t Size() const { return keyframes_.size(); }

  /// Drops the frame and tracking reference of every keyframe not in `keep` (ids).
  void Compact(const std::vector<std::int64_t>& keep);

  void AddEdge(const PoseGraphEdge& edge) { poses_.AddEdge(edge); }
  bool HasEdge(std::int64_t a, std::int64_t b) const;
  EdgeCounts CountEdges() const;
  /// The pose graph, for the optimiser (the only place poses change).
  PoseGraph& Poses() { return poses_; }
  const PoseGraph& Poses() const { return poses_; }

  /// World points of every keyframe's confirmed depth through its current pose; `camera`
  /// is the (level-0) camera of the keyframes.
  std::vector<Eigen::Vector3f> MapPoints(const PinholeCamera& camera) const;
  /// The same points one at a time with their intensity (no copy of the whole cloud).
  void ForEachMapPoint(const PinholeCamera& camera,
                       const std::function<void(const MapPoint&)>& fn) const;
  /// Memory held by the keyframes (frozen depth, tracking references, frame pyramids).
  std::size_t Bytes() const;
  void Clear();

 private:
  std::map<std::int64_t, std::shared_ptr<const Keyframe>> keyframes_;
  std::map<std::int64_t, int> map_of_;
  PoseGraph poses_;
};

}  // namespace parallax
