#include "vola/error.hpp"
#include "vola/file.hpp"
#include "vola/learn/classifier.hpp"

namespace vola::learn {

std::vector<Sample> load_samples(const std::vector<DatasetEntry>& entries, int min_side) {
  std::vector<Sample> samples;
  samples.reserve(entries.size());
  for (const auto& entry : entries) {
    Tree tree = read(entry.path);
    if (tree.side() < std::uint32_t(min_side))
      throw InvalidArgument(entry.path + ": a " + std::to_string(tree.side()) + "^3 grid; the networks read " +
                            std::to_string(min_side) + "^3 or finer (depth 3 or more), as `vola dataset` writes");
    samples.push_back({std::move(tree), entry.label});
  }
  return samples;
}

}  // namespace vola::learn
