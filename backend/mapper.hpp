#pragma once
// The mapping stage: owns the current keyframe's mutable inverse-depth map, the depth filter
// and the update-direction check; publishes an immutable TrackingReference whenever the map
// changes; keeps the mutable maps of the most recent keyframes for recovery; freezes a
// keyframe for the graph when it is finished.

#include <cstdint>
#include <deque>
#include <memory>
#include <utility>
#include <vector>

#include "backend/keyframe_graph.hpp"
#include "backend/update_direction.hpp"
#include "depth/depth_filter.hpp"
#include "tracking/tracking_reference.hpp"
#include "tracking/tracking_result.hpp"

namespace parallax {

class Mapper {
 public:
  /// `recent_keyframes`: how many finished keyframes keep their mutable map for recovery.
  Mapper(const PinholeCamera& camera, const DepthFilterOptions& depth,
         const UpdateDirectionOptions& update_direction, const TrackingReferenceOptions& reference,
         int recent_keyframes);

  bool HasMap() const { return map_ != nullptr; }
  /// Preconditions for the accessors below: HasMap().
  InverseDepthMap& Map() { return *map_; }
  const InverseDepthMap& Map() const { return *map_; }
  std::int64_t KeyframeId() const;
  /// The published reference of the current map (immutable; shared with the graph).
  const std::shared_ptr<const TrackingReference>& Reference() const { return reference_; }

  /// Makes `map` the current one (its keyframe may be the current one, e.g. a new start),
  /// and publishes its reference. The previous map is dropped (see Retire).
  void SetMap(InverseDepthMap map);
  /// Puts back a map and the reference published for it (a saved start).
  void Restore(std::unique_ptr<InverseDepthMap> map,
               std::shared_ptr<const TrackingReference> reference);
  /// Publishes the current map's reference again (after depth changed).
  void PublishReference();
  /// One stereo update of the current map from a tracked frame seen at T_kf_update.
  DepthUpdateStats Update(const Frame& frame, const SE3d& T_kf_update,
                          const TrackingResult& tracked);
  /// The depth of a new keyframe at `frame` (propagated and scale-normalised) and the scale s
  /// the normalisation multiplied inverse depths by; the new map takes the current one's
  /// working memory. Throws NumericalDivergence when the propagated map diverged (its mean
  /// inverse depth is not finite).
  std::pair<InverseDepthMap, float> Propagate(const std::shared_ptr<const Frame>& frame,
                                              const TrackingResult& tracked,
                                              PropagationStats* stats = nullptr);
  /// The current keyframe as the graph keeps it (frozen sparse depth, image, reference).
  std::shared_ptr<Keyframe> Freeze() const;
  /// The current map becomes the newest recent one (the oldest beyond the limit is dropped);
  /// afterwards there is no current map until SetMap.
  void Retire();
  std::size_t NumRecent() const { return recent_.size(); }
  const TrackingReference& RecentReference(std::size_t i) const { return *recent_[i].reference; }
  std::int64_t RecentKeyframeId(std::size_t i) const;
  /// Recent keyframe i becomes current again; the current one takes its place, moved to the
  /// front of the recent ones.
  void ReturnTo(std::size_t i);
  /// Ids of the current and the recent keyframes (those whose full data is kept).
  std::vector<std::int64_t> LiveKeyframeIds() const;
  void Clear();

  DepthFilter& Filter() { return depth_filter_; }
  UpdateDirection& Direction() { return update_direction_; }

 private:
  struct Recent {
    std::unique_ptr<InverseDepthMap> map;
    std::shared_ptr<const TrackingReference> reference;
  };
  DepthFilter depth_filter_;
  UpdateDirection update_direction_;
  TrackingReferenceOptions reference_options_;
  int recent_keyframes_;
  std::unique_ptr<InverseDepthMap> map_;
  std::shared_ptr<const TrackingReference> reference_;
  std::deque<Recent> recent_;  ///< newest first
  /// The arrays of the last map dropped, which the next propagated map reuses.
  RecycledArrays spare_arrays_;
};

}  // namespace parallax
