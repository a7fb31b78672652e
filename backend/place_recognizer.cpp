#include "backend/place_recognizer.hpp"

#include <algorithm>
#include <limits>

#include "core/check.hpp"

namespace parallax {

void PlaceRecognitionOptions::Check() const {
  orb.Check();
  CheckOption(direct_index_level >= 0, "PlaceRecognitionOptions", "direct_index_level",
              "must be >= 0");
  CheckOption(max_match_distance >= 0 && max_match_distance <= 256, "PlaceRecognitionOptions",
              "max_match_distance", "must be in [0, 256]");
  CheckOption(match_ratio > 0.0f && match_ratio <= 1.0f, "PlaceRecognitionOptions", "match_ratio",
              "must be in (0, 1]");
}

std::size_t PlaceEntry::Bytes() const {
  std::size_t bytes = features.Bytes() + bow.capacity() * sizeof(bow[0]);
  for (const auto& node : direct) bytes += sizeof(node) + node.second.capacity() * 4;
  return bytes;
}

std::vector<std::pair<std::uint32_t, std::uint32_t>> MatchByNodes(
    const PlaceEntry& a, const PlaceEntry& b, const PlaceRecognitionOptions& options) {
  // best_for_b[j]: (distance, feature of a) of the best a-feature that chose j.
  std::vector<std::pair<int, std::int64_t>> best_for_b(b.features.Size(), {257, -1});
  auto ia = a.direct.begin();
  auto ib = b.direct.begin();
  while (ia != a.direct.end() && ib != b.direct.end()) {
    if (ia->first != ib->first) {
      ia->first < ib->first ? ++ia : ++ib;
      continue;
    }
    for (const std::uint32_t i : ia->second) {
      int best = std::numeric_limits<int>::max(), second = best;
      std::uint32_t best_j = 0;
      for (const std::uint32_t j : ib->second) {
        const int d = Hamming(a.features.descriptors[i], b.features.descriptors[j]);
        if (d < best) {
          second = best;
          best = d;
          best_j = j;
        } else if (d < second) {
          second = d;
        }
      }
      if (best > options.max_match_distance) continue;
      if (static_cast<float>(best) >= options.match_ratio * static_cast<float>(second)) continue;
      if (best < best_for_b[best_j].first) best_for_b[best_j] = {best, i};
    }
    ++ia;
    ++ib;
  }
  std::vector<std::pair<std::uint32_t, std::uint32_t>> matches;
  for (std::uint32_t j = 0; j < best_for_b.size(); ++j) {
    if (best_for_b[j].second >= 0) {
      matches.emplace_back(static_cast<std::uint32_t>(best_for_b[j].second), j);
    }
  }
  std::sort(matches.begin(), matches.end());
  return matches;
}

PlaceRecognizer::PlaceRecognizer(const Vocabulary& vocabulary,
                                 const PlaceRecognitionOptions& options)
    : vocabulary_(&vocabulary), options_(options) {
  options_.Check();
}

std::shared_ptr<const PlaceEntry> PlaceRecognizer::Describe(const ImageU8& image) const {
  return Describe(ExtractOrb(image, options_.orb));
}

std::shared_ptr<const PlaceEntry> PlaceRecognizer::Describe(OrbFeatures features) const {
  auto entry = std::make_shared<PlaceEntry>();
  entry->features = std::move(features);
  entry->bow = vocabulary_->Transform(entry->features.descriptors, &entry->direct,
                                      options_.direct_index_level);
  return entry;
}

void PlaceRecognizer::Add(std::int64_t id, std::shared_ptr<const PlaceEntry> entry) {
  CheckArgument(entry != nullptr, "PlaceRecognizer::Add: no entry");
  database_.Add(id, entry->bow);
  entries_[id] = std::move(entry);
}

void PlaceRecognizer::Remove(std::int64_t id) {
  database_.Remove(id);
  entries_.erase(id);
}

std::size_t PlaceRecognizer::Bytes() const {
  std::size_t bytes = 0;
  for (const auto& [id, entry] : entries_) bytes += entry->Bytes();
  return bytes;
}

void PlaceRecognizer::Clear() {
  entries_.clear();
  database_.Clear();
}

}  // namespace parallax
