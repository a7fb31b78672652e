// A fuzz target without libFuzzer: every file of the given corpus folders, then MUTATIONS
// inputs made from them with a fixed seed (bytes flipped, set, inserted or deleted, ends cut,
// two inputs spliced), the same inputs every run. ctest runs each target this way (label
// fuzz), so the README's test command and CI's ASan+UBSan stage replay every regression
// input; scripts/fuzz runs the coverage-guided search with libFuzzer (docs/reliability.md).
// Usage: fuzz_<target>_replay MUTATIONS CORPUS_DIR...
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <string>
#include <vector>

#include "fuzz_input.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size);

namespace {

using Bytes = std::vector<std::uint8_t>;

/// libFuzzer's -max_len in scripts/fuzz.
constexpr std::size_t kMaxLength = 65536;

std::vector<Bytes> ReadCorpus(int argc, char** argv) {
  std::vector<std::filesystem::path> files;
  for (int i = 2; i < argc; ++i) {
    for (const auto& entry : std::filesystem::directory_iterator(argv[i])) {
      if (entry.is_regular_file()) files.push_back(entry.path());
    }
  }
  std::sort(files.begin(), files.end());  // directory order is the file system's
  std::vector<Bytes> corpus;
  for (const auto& file : files) {
    std::ifstream in(file, std::ios::binary);
    corpus.emplace_back(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }
  return corpus;
}

std::size_t Below(std::mt19937_64& rng, std::size_t n) {
  return n == 0 ? 0 : static_cast<std::size_t>(rng() % n);
}

/// One to four edits of a corpus input (or of two spliced).
Bytes Mutate(const std::vector<Bytes>& corpus, std::mt19937_64& rng) {
  Bytes bytes = corpus[Below(rng, corpus.size())];
  const std::size_t edits = 1 + Below(rng, 4);
  for (std::size_t e = 0; e < edits; ++e) {
    const std::size_t at = Below(rng, bytes.size());
    switch (Below(rng, 6)) {
      case 0:
        if (!bytes.empty())
          bytes[at] = static_cast<std::uint8_t>(bytes[at] ^ (1U << Below(rng, 8)));
        break;
      case 1:
        if (!bytes.empty()) bytes[at] = static_cast<std::uint8_t>(rng());
        break;
      case 2:
        bytes.insert(bytes.begin() + static_cast<std::ptrdiff_t>(at),
                     static_cast<std::uint8_t>(rng()));
        break;
      case 3:
        if (!bytes.empty()) bytes.erase(bytes.begin() + static_cast<std::ptrdiff_t>(at));
        break;
      case 4:
        bytes.resize(at);
        break;
      default: {
        const Bytes& other = corpus[Below(rng, corpus.size())];
        const std::size_t from = Below(rng, other.size());
        bytes.resize(at);
        bytes.insert(bytes.end(), other.begin() + static_cast<std::ptrdiff_t>(from), other.end());
      }
    }
  }
  if (bytes.size() > kMaxLength) bytes.resize(kMaxLength);
  return bytes;
}

void Run(const Bytes& bytes) {
  // libFuzzer passes a valid pointer for an empty input too.
  const std::uint8_t empty = 0;
  LLVMFuzzerTestOneInput(bytes.empty() ? &empty : bytes.data(), bytes.size());
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: %s MUTATIONS CORPUS_DIR...\n", argv[0]);
    return 2;
  }
  try {
    const long mutations = std::strtol(argv[1], nullptr, 10);
    const std::vector<Bytes> corpus = ReadCorpus(argc, argv);
    if (corpus.empty() || mutations < 0) {
      std::fprintf(stderr, "%s: no corpus files, or a negative number of mutations\n", argv[0]);
      return 2;
    }
    for (const Bytes& input : corpus) Run(input);
    std::mt19937_64 rng(1);
    for (long i = 0; i < mutations; ++i) Run(Mutate(corpus, rng));
    std::filesystem::remove_all(parallax::fuzz::Scratch());
    std::printf("%zu corpus inputs and %ld mutations: no finding\n", corpus.size(), mutations);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s: %s\n", argv[0], e.what());
    return 1;
  }
  return 0;
}
