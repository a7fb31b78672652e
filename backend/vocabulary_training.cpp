// Training of the k-majority vocabulary tree (docs/place_recognition.md, "Vocabulary").

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <deque>
#include <limits>
#include <random>
#include <set>

#include "backend/vocabulary.hpp"
#include "core/check.hpp"

namespace parallax {

void VocabularyTrainingOptions::Check() const {
  CheckOption(branching >= 2 && branching <= 255, "VocabularyTrainingOptions", "branching",
              "must be in [2, 255]");
  CheckOption(depth >= 1 && depth <= 16, "VocabularyTrainingOptions", "depth",
              "must be in [1, 16]");
  CheckOption(max_iterations >= 1, "VocabularyTrainingOptions", "max_iterations", "must be >= 1");
  CheckOption(std::pow(branching, depth) <= 2e7, "VocabularyTrainingOptions", "branching",
              "^depth must be <= 2e7 words");
}

/// Builds the tree breadth-first, so that the nodes come out in file order.
class VocabularyBuilder {
 public:
  VocabularyBuilder(const std::vector<OrbDescriptor>& all, const VocabularyTrainingOptions& o)
      : all_(all), options_(o), random_(o.seed) {}

  Vocabulary Build(const std::vector<std::vector<OrbDescriptor>>& images) {
    Vocabulary& v = vocabulary_;
    v.branching_ = options_.branching;
    v.depth_ = options_.depth;
    v.training_images_ = static_cast<std::uint32_t>(images.size());
    AddNode(std::numeric_limits<std::uint32_t>::max(), OrbDescriptor{}, false);
    std::vector<std::uint32_t> everything(all_.size());
    for (std::uint32_t i = 0; i < everything.size(); ++i) everything[i] = i;
    std::deque<std::pair<std::uint32_t, std::vector<std::uint32_t>>> pending;
    pending.emplace_back(0, std::move(everything));
    std::vector<std::uint8_t> level{0};
    while (!pending.empty()) {
      auto [node, members] = std::move(pending.front());
      pending.pop_front();
      const int child_level = level[node] + 1;
      for (auto& cluster : Split(members)) {
        const bool leaf = child_level == options_.depth || AllEqual(cluster);
        const std::uint32_t child = AddNode(node, Majority(cluster), leaf);
        level.push_back(static_cast<std::uint8_t>(child_level));
        if (!leaf) pending.emplace_back(child, std::move(cluster));
      }
    }
    v.Index("training");
    SetIdf(images);
    return std::move(vocabulary_);
  }

 private:
  std::uint32_t AddNode(std::uint32_t parent, const OrbDescriptor& d, bool leaf) {
    Vocabulary& v = vocabulary_;
    v.parent_.push_back(parent);
    v.is_leaf_.push_back(leaf ? 1 : 0);
    v.descriptor_.push_back(d);
    v.node_weight_.push_back(0.0f);
    return static_cast<std::uint32_t>(v.parent_.size() - 1);
  }

  double Uniform() { return static_cast<double>(random_() >> 11) * (1.0 / 9007199254740992.0); }

  bool AllEqual(const std::vector<std::uint32_t>& members) const {
    return std::all_of(members.begin(), members.end(),
                       [&](std::uint32_t m) { return all_[m] == all_[members.front()]; });
  }

  /// Bitwise majority (a bit is set when more than half of the members have it).
  OrbDescriptor Majority(const std::vector<std::uint32_t>& members) const {
    std::array<std::uint32_t, 256> counts{};
    for (const std::uint32_t m : members) {
      for (std::size_t w = 0; w < 4; ++w) {
        for (std::uint64_t bits = all_[m][w]; bits != 0; bits &= bits - 1) {
          ++counts[w * 64 + static_cast<std::size_t>(std::countr_zero(bits))];
        }
      }
    }
    OrbDescriptor d{};
    for (std::size_t b = 0; b < 256; ++b) {
      if (2 * std::size_t{counts[b]} > members.size()) d[b / 64] |= std::uint64_t{1} << (b % 64);
    }
    return d;
  }

  /// k-means++ seeding (probability proportional to the squared Hamming distance).
  std::vector<OrbDescriptor> Seeds(const std::vector<std::uint32_t>& members) {
    std::vector<OrbDescriptor> centres{
        all_[members[static_cast<std::size_t>(Uniform() * static_cast<double>(members.size()))]]};
    std::vector<double> d2(members.size(), std::numeric_limits<double>::max());
    while (static_cast<int>(centres.size()) < options_.branching) {
      double total = 0.0;
      for (std::size_t i = 0; i < members.size(); ++i) {
        const double d = Hamming(all_[members[i]], centres.back());
        d2[i] = std::min(d2[i], d * d);
        total += d2[i];
      }
      if (total <= 0.0) break;  // fewer distinct descriptors than k
      double pick = Uniform() * total;
      std::size_t i = 0;
      for (; i + 1 < members.size() && pick >= d2[i]; ++i) pick -= d2[i];
      centres.push_back(all_[members[i]]);
    }
    return centres;
  }

  /// The members split into at most k clusters (one per member when there are at most k).
  std::vector<std::vector<std::uint32_t>> Split(const std::vector<std::uint32_t>& members) {
    std::vector<std::vector<std::uint32_t>> clusters;
    if (static_cast<int>(members.size()) <= options_.branching) {
      for (const std::uint32_t m : members) clusters.push_back({m});
      return clusters;
    }
    std::vector<OrbDescriptor> centres = Seeds(members);
    std::vector<std::uint32_t> assignment(members.size(), 0);
    for (int iteration = 0; iteration < options_.max_iterations; ++iteration) {
      bool changed = iteration == 0;
      for (std::size_t i = 0; i < members.size(); ++i) {
        std::uint32_t best = 0;
        int best_d = std::numeric_limits<int>::max();
        for (std::uint32_t c = 0; c < centres.size(); ++c) {
          const int d = Hamming(all_[members[i]], centres[c]);
          if (d < best_d) {
            best_d = d;
            best = c;
          }
        }
        changed |= assignment[i] != best;
        assignment[i] = best;
      }
      clusters.assign(centres.size(), {});
      for (std::size_t i = 0; i < members.size(); ++i)
        clusters[assignment[i]].push_back(members[i]);
      if (!changed) break;
      for (std::size_t c = 0; c < centres.size(); ++c) {
        if (!clusters[c].empty()) centres[c] = Majority(clusters[c]);
      }
    }
    std::erase_if(clusters, [](const auto& c) { return c.empty(); });
    return clusters;
  }

  /// idf_i = ln(N / N_i) over the N training images, N_i of which have word i (by lookup,
  /// as at run time); a word no training image reaches by lookup counts as seen once.
  void SetIdf(const std::vector<std::vector<OrbDescriptor>>& images) {
    Vocabulary& v = vocabulary_;
    std::vector<std::uint32_t> images_with(v.NumWords(), 0);
    for (const auto& image : images) {
      std::set<std::uint32_t> words;
      for (const OrbDescriptor& d : image) words.insert(v.Lookup(d));
      for (const std::uint32_t w : words) ++images_with[w];
    }
    const double n = static_cast<double>(images.size());
    for (std::size_t w = 0; w < v.NumWords(); ++w) {
      const double idf = std::log(n / std::max<double>(1.0, images_with[w]));
      v.node_weight_[v.word_node_[w]] = static_cast<float>(idf);
      v.word_weight_[w] = static_cast<float>(idf);
    }
  }

  const std::vector<OrbDescriptor>& all_;
  VocabularyTrainingOptions options_;
  std::mt19937_64 random_;  // bit-exact by the standard; distributions derived above
  Vocabulary vocabulary_;
};

Vocabulary Vocabulary::Train(const std::vector<std::vector<OrbDescriptor>>& images,
                             const VocabularyTrainingOptions& options) {
  options.Check();
  std::vector<OrbDescriptor> all;
  for (const auto& image : images) all.insert(all.end(), image.begin(), image.end());
  CheckArgument(!all.empty(), "Vocabulary::Train: no descriptors to train on");
  return VocabularyBuilder(all, options).Build(images);
}

}  // namespace parallax
