#include "backend/keyframe_database.hpp"

#include <algorithm>

namespace parallax {

void KeyframeDatabase::Add(std::int64_t id, const BowVector& bow) {
  Remove(id);
  std::uint32_t slot = 0;
  if (!free_slots_.empty()) {
    slot = free_slots_.back();
    free_slots_.pop_back();
  } else {
    slot = static_cast<std::uint32_t>(id_of_slot_.size());
    id_of_slot_.push_back(-1);
    vector_of_slot_.emplace_back();
    score_.push_back(0.0f);
    common_.push_back(0);
  }
  id_of_slot_[slot] = id;
  vector_of_slot_[slot] = bow;
  slot_of_[id] = slot;
  for (const auto& [word, weight] : bow) {
    if (word >= inverted_.size()) inverted_.resize(word + 1);
    inverted_[word].push_back({slot, weight});
  }
}

void KeyframeDatabase::Remove(std::int64_t id) {
  const auto it = slot_of_.find(id);
  if (it == slot_of_.end()) return;
  const std::uint32_t slot = it->second;
  for (const auto& entry : vector_of_slot_[slot]) {
    std::erase_if(inverted_[entry.first], [&](const Posting& p) { return p.slot == slot; });
  }
  vector_of_slot_[slot].clear();
  id_of_slot_[slot] = -1;
  free_slots_.push_back(slot);
  slot_of_.erase(it);
}

void KeyframeDatabase::Clear() { *this = KeyframeDatabase(); }

std::vector<DatabaseMatch> KeyframeDatabase::Query(
    const BowVector& query, const std::function<bool(std::int64_t)>& excluded,
    std::size_t max_results, double min_score) const {
  touched_.clear();
  for (const auto& [word, q] : query) {
    if (word >= inverted_.size()) continue;
    for (const Posting& p : inverted_[word]) {
      if (common_[p.slot] == 0) touched_.push_back(p.slot);
      ++common_[p.slot];
      // For non-negative weights (|q| + |v| - |q - v|) / 2 = min(q, v).
      score_[p.slot] += std::min(q, p.weight);
    }
  }
  std::vector<DatabaseMatch> matches;
  for (const std::uint32_t slot : touched_) {
    const std::int64_t id = id_of_slot_[slot];
    if (score_[slot] >= min_score && !(excluded && excluded(id))) {
      matches.push_back({id, score_[slot], common_[slot]});
    }
    score_[slot] = 0.0f;
    common_[slot] = 0;
  }
  std::sort(matches.begin(), matches.end(), [](const DatabaseMatch& a, const DatabaseMatch& b) {
    return a.score != b.score ? a.score > b.score : a.keyframe_id < b.keyframe_id;
  });
  if (matches.size() > max_results) matches.resize(max_results);
  return matches;
}

}  // namespace parallax
