#include "backend/mapper.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

#include "depth/depth_map.hpp"

namespace parallax {

Mapper::Mapper(const PinholeCamera& camera, const DepthFilterOptions& depth,
               const UpdateDirectionOptions& update_direction,
               const TrackingReferenceOptions& reference, int recent_keyframes)
    : depth_filter_(depth),
      update_direction_(camera, update_direction),
      reference_options_(reference),
      recent_keyframes_(recent_keyframes) {}

std::int64_t Mapper::KeyframeId() const { return map_->KeyframePtr()->Id(); }

std::int64_t Mapper::RecentKeyframeId(std::size_t i) const {
  return recent_[i].map->KeyframePtr()->Id();
}

void Mapper::SetMap(InverseDepthMap map) {
  map_ = std::make_unique<InverseDepthMap>(std::move(map));
  PublishReference();
}

void Mapper::Restore(std::unique_ptr<InverseDepthMap> map,
                     std::shared_ptr<const TrackingReference> reference) {
  map_ = std::move(map);
  reference_ = std::move(reference);
}

void Mapper::PublishReference() {
  const ReferenceDepth smoothed{map_->Width(), map_->Height(), map_->idepth_smoothed.data(),
                                map_->variance_smoothed.data(), map_->valid.data()};
  reference_ =
      std::make_shared<const TrackingReference>(map_->KeyframePtr(), smoothed, reference_options_);
}

DepthUpdateStats Mapper::Update(const Frame& frame, const SE3d& T_kf_update,
                                const TrackingResult& tracked) {
  const StereoFrame stereo{&frame, T_kf_update.Inverse(), tracked.affine.Gain(), tracked.affine.b,
                           static_cast<float>(1.0 - tracked.stats.good_ratio)};
  return depth_filter_.Update(map_.get(), stereo);
}

std::pair<InverseDepthMap, float> Mapper::Propagate(const std::shared_ptr<const Frame>& frame,
                                                    const TrackingResult& tracked,
                                                    PropagationStats* stats) {
  // The current map is finished next (or, if this throws, updated again with new memory):
  // its working memory moves on to the new map, with the arrays of the last map dropped.
  map_->scratch.recycled = std::exchange(spare_arrays_, {});
  InverseDepthMap next =
      depth_filter_.Propagate(*map_, frame, tracked.T_kf_frame.Inverse(), tracked.affine.Gain(),
                              tracked.affine.b, stats, std::move(map_->scratch));
  const float s = depth_filter_.NormalizeScale(&next);
  return {std::move(next), s};
}

std::shared_ptr<Keyframe> Mapper::Freeze() const {
  auto keyframe = std::make_shared<Keyframe>();
  keyframe->id = map_->KeyframePtr()->Id();
  keyframe->timestamp = map_->KeyframePtr()->Timestamp();
  keyframe->frame = map_->KeyframePtr();
  const PyramidLevel& level0 = keyframe->frame->Level(0);
  keyframe->image = ImageU8(level0.Width(), level0.Height());
  for (int y = 0; y < level0.Height(); ++y) {
    for (int x = 0; x < level0.Width(); ++x) {
      keyframe->image(x, y) = static_cast<std::uint8_t>(std::lround(level0.intensity(x, y)));
    }
  }
  keyframe->depth = FrozenDepth::FromMap(*map_);
  keyframe->reference = reference_;
  return keyframe;
}

void Mapper::Retire() {
  if (map_) map_->scratch.Release();  // no longer updated (a return to it allocates again)
  if (recent_keyframes_ > 0) {
    recent_.push_front({std::move(map_), std::move(reference_)});
    if (static_cast<int>(recent_.size()) > recent_keyframes_) {
      spare_arrays_ = recent_.back().map->TakeArrays();  // the next new map's memory
      recent_.pop_back();
    }
  } else if (map_) {
    spare_arrays_ = map_->TakeArrays();
  }
  map_.reset();
  reference_.reset();
}

void Mapper::ReturnTo(std::size_t i) {
  const auto it = recent_.begin() + static_cast<std::ptrdiff_t>(i);
  std::swap(map_, it->map);
  std::swap(reference_, it->reference);
  std::rotate(recent_.begin(), it, std::next(it));
  update_direction_.Reset();  // its features are of the keyframe left behind
}

std::vector<std::int64_t> Mapper::LiveKeyframeIds() const {
  std::vector<std::int64_t> ids;
  if (map_) ids.push_back(KeyframeId());
  for (const Recent& r : recent_) ids.push_back(r.map->KeyframePtr()->Id());
  return ids;
}

void Mapper::Clear() {
  recent_.clear();
  spare_arrays_ = {};
  map_.reset();
  reference_.reset();
}

}  // namespace parallax
