#pragma once
// A bag-of-words vocabulary for ORB descriptors: a hierarchical k-majority tree whose leaves
// are the words, with idf weights (DBoW-style; docs/place_recognition.md).

#include <cstdint>
#include <span>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "backend/orb_features.hpp"

namespace parallax {

/// Sparse tf-idf vector: (word id, weight) sorted by word id, L1-normalised (weights sum
/// to 1; empty when no descriptor fell on a weighted word).
using BowVector = std::vector<std::pair<std::uint32_t, float>>;

/// The direct index of one image: (tree node at the direct-index level, feature indices
/// that descend through it), sorted by node; matching compares only features sharing a node.
using FeatureVector = std::vector<std::pair<std::uint32_t, std::vector<std::uint32_t>>>;

/// Similarity of two L1-normalised vectors, 1 - |a - b|_1 / 2 in [0, 1] (DBoW's L1 score),
/// computed over the shared words only.
double ScoreL1(const BowVector& a, const BowVector& b);

struct VocabularyTrainingOptions {
  int branching = 10;  ///< k: children per node
  int depth = 4;       ///< L: levels below the root (k^L words at most)
  /// k-majority iterations per node (assignments usually settle in fewer).
  int max_iterations = 10;
  std::uint64_t seed = 1;  ///< our own generator: the same file on every platform

  void Check() const;
};

/// Thrown when a vocabulary file cannot be read; the message names the file and the
/// byte offset of the problem.
class VocabularyError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class Vocabulary {
 public:
  /// Trains on the descriptors of a set of images (one vector per image; idf is counted
  /// over images). Deterministic for given input and options. Throws std::invalid_argument
  /// when there are no descriptors.
  static Vocabulary Train(const std::vector<std::vector<OrbDescriptor>>& images,
                          const VocabularyTrainingOptions& options);
  /// Parses the binary format (docs/place_recognition.md); `source` names it in errors.
  static Vocabulary FromBytes(std::span<const std::uint8_t> bytes, const std::string& source);
  /// Reads a vocabulary file; throws VocabularyError.
  static Vocabulary Load(const std::string& path);
  /// The vocabulary compiled into the library (backend/vocabulary/), parsed once.
  static const Vocabulary& Default();

  std::vector<std::uint8_t> ToBytes() const;
  /// Writes atomically (temporary file + rename); throws std::runtime_error naming the path.
  void Save(const std::string& path) const;

  /// The word of one descriptor (greedy descent, k Hamming distances per level); the node
  /// passed at `direct_level` (0 = root) goes to `node_at_level` when it is not null.
  std::uint32_t Lookup(const OrbDescriptor& descriptor, int direct_level = 0,
                       std::uint32_t* node_at_level = nullptr) const;
  /// tf-idf vector of an image's descriptors and, when `features` is not null, its direct
  /// index at `direct_level`.
  BowVector Transform(std::span<const OrbDescriptor> descriptors, FeatureVector* features = nullptr,
                      int direct_level = 2) const;

  int Branching() const { return branching_; }
  int Depth() const { return depth_; }
  std::size_t NumNodes() const { return parent_.size(); }
  std::size_t NumWords() const { return word_node_.size(); }
  std::uint32_t TrainingImages() const { return training_images_; }
  /// idf of a word (0: it occurred in every training image, a stop word).
  float Weight(std::uint32_t word) const { return word_weight_[word]; }

 private:
  friend class VocabularyBuilder;
  /// Fills first_child_, num_children_, word ids and levels from parent_ and is_leaf_;
  /// throws VocabularyError (naming `source`) when the tree is malformed.
  void Index(const std::string& source);

  int branching_ = 0;
  int depth_ = 0;
  std::uint32_t training_images_ = 0;
  // Nodes in breadth-first order (node 0 is the root; children of a node are consecutive).
  std::vector<std::uint32_t> parent_;
  std::vector<std::uint8_t> is_leaf_;
  std::vector<OrbDescriptor> descriptor_;
  std::vector<float> node_weight_;  ///< idf of a leaf, 0 for inner nodes
  std::vector<std::uint32_t> first_child_;
  std::vector<std::uint8_t> num_children_;
  std::vector<std::uint8_t> level_;
  std::vector<std::int32_t> node_word_;  ///< word id of a leaf, -1 for inner nodes
  std::vector<std::uint32_t> word_node_;
  std::vector<float> word_weight_;
};

}  // namespace parallax
