#include "leaf_blocks.hpp"

#include <bit>

namespace vola::analysis::detail {

LeafBlocks::LeafBlocks(const Tree& tree) : index_(tree.empty() ? 0 : tree.occupancy(tree.depth() - 1).size()) {
  if (tree.empty()) return;
  blocks_.reserve(tree.occupancy(tree.depth() - 1).size());
  std::uint64_t rank = 0;
  tree.for_each_block(tree.depth() - 1, [&](std::size_t, std::uint64_t word, std::uint32_t ox, std::uint32_t oy,
                                            std::uint32_t oz) {
    index_.at(pack_block(ox / 4, oy / 4, oz / 4)) = blocks_.size();
    blocks_.push_back({ox / 4, oy / 4, oz / 4, word, rank});
    rank += static_cast<std::uint64_t>(std::popcount(word));
  });
}

}  // namespace vola::analysis::detail
