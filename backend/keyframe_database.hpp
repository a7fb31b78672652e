#pragma once
// The keyframe database of the place recogniser: an inverted index (word -> keyframes that
// contain it) scored with DBoW's L1 score (docs/place_recognition.md, "Database").

#include <cstdint>
#include <functional>
#include <map>
#include <vector>

#include "backend/vocabulary.hpp"

namespace parallax {

/// One keyframe found by a query.
struct DatabaseMatch {
  std::int64_t keyframe_id = 0;
  double score = 0.0;    ///< ScoreL1 with the query, in [0, 1]
  int common_words = 0;  ///< words the two vectors share
};

class KeyframeDatabase {
 public:
  /// Adds (or replaces) the vector of keyframe `id`.
  void Add(std::int64_t id, const BowVector& bow);
  void Remove(std::int64_t id);
  bool Contains(std::int64_t id) const { return slot_of_.count(id) > 0; }
  std::size_t Size() const { return slot_of_.size(); }
  void Clear();

  /// The keyframes sharing a word with `query`, except those `excluded` says no to, scored
  /// with ScoreL1 (sum over shared words of min(q_i, v_i)), best first (ties: lower id), at
  /// most `max_results`, none below `min_score`. Cost grows with the lengths of the
  /// query words' lists, not with the number of keyframes.
  std::vector<DatabaseMatch> Query(const BowVector& query,
                                   const std::function<bool(std::int64_t)>& excluded,
                                   std::size_t max_results, double min_score = 0.0) const;

 private:
  struct Posting {
    std::uint32_t slot;
    float weight;
  };
  std::vector<std::vector<Posting>> inverted_;  ///< by word
  std::map<std::int64_t, std::uint32_t> slot_of_;
  std::vector<std::int64_t> id_of_slot_;  ///< -1 for a free slot
  std::vector<BowVector> vector_of_slot_;
  std::vector<std::uint32_t> free_slots_;
  // Query scratch, sized with the slots (mutable: queries are logically const).
  mutable std::vector<float> score_;
  mutable std::vector<int> common_;
  mutable std::vector<std::uint32_t> touched_;
};

}  // namespace parallax
