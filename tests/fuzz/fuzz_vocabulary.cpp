// Vocabulary files (binary, checksummed): parsed, and a valid one used for a lookup. Corrupt
// input must be rejected with VocabularyError, never crash or allocate without bound.
#include "backend/vocabulary.hpp"
#include "fuzz_input.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace parallax;
  fuzz::Accepts([&] {
    const Vocabulary v = Vocabulary::FromBytes(std::span(data, size), "fuzz.pxvoc");
    const std::vector<OrbDescriptor> descriptors = {OrbDescriptor{}, OrbDescriptor{~0ull, 1, 2, 3}};
    FeatureVector direct;
    v.Transform(descriptors, &direct, 1);
  });
  return 0;
}
