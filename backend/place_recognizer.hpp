#pragma once
// Place recognition data of the keyframes: ORB features, bag-of-words vectors and their
// direct index, with the keyframe database (docs/place_recognition.md).

#include <cstdint>
#include <map>
#include <memory>
#include <utility>
#include <vector>

#include "backend/keyframe_database.hpp"
#include "backend/orb_features.hpp"
#include "backend/vocabulary.hpp"

namespace parallax {

struct PlaceRecognitionOptions {
  OrbOptions orb;  ///< as the vocabulary was trained with
  /// Tree level (0 = root) whose nodes group features for matching (DBoW's direct index).
  int direct_index_level = 2;
  /// A match needs Hamming distance at most this and a best/second-best ratio below
  /// `match_ratio` within its node (ORB-SLAM's SearchByBoW values).
  int max_match_distance = 50;
  float match_ratio = 0.75f;

  void Check() const;
};

/// What the recogniser keeps of one keyframe (immutable once made).
struct PlaceEntry {
  OrbFeatures features;
  BowVector bow;
  FeatureVector direct;

  std::size_t Bytes() const;
};

/// Index pairs (feature in a, feature in b), each feature used once, matched only within
/// shared direct-index nodes.
std::vector<std::pair<std::uint32_t, std::uint32_t>> MatchByNodes(
    const PlaceEntry& a, const PlaceEntry& b, const PlaceRecognitionOptions& options);

class PlaceRecognizer {
 public:
  /// `vocabulary` must outlive the recogniser.
  explicit PlaceRecognizer(const Vocabulary& vocabulary,
                           const PlaceRecognitionOptions& options = {});

  /// Features and vectors of an image (not stored).
  std::shared_ptr<const PlaceEntry> Describe(const ImageU8& image) const;
  /// Vectors of features extracted earlier (e.g. read from a map file), not stored.
  std::shared_ptr<const PlaceEntry> Describe(OrbFeatures features) const;
  /// Stores the entry of keyframe `id` and adds it to the database.
  void Add(std::int64_t id, std::shared_ptr<const PlaceEntry> entry);
  void Remove(std::int64_t id);
  bool Contains(std::int64_t id) const { return entries_.count(id) > 0; }
  /// Throws std::out_of_range for an unknown id.
  const PlaceEntry& Entry(std::int64_t id) const { return *entries_.at(id); }
  const std::shared_ptr<const PlaceEntry>& EntryPtr(std::int64_t id) const {
    return entries_.at(id);
  }
  const KeyframeDatabase& Database() const { return database_; }
  const PlaceRecognitionOptions& Options() const { return options_; }
  std::size_t Size() const { return entries_.size(); }
  std::size_t Bytes() const;
  void Clear();

 private:
  const Vocabulary* vocabulary_;
  PlaceRecognitionOptions options_;
  std::map<std::int64_t, std::shared_ptr<const PlaceEntry>> entries_;
  KeyframeDatabase database_;
};

}  // namespace parallax
