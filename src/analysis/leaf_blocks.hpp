// The leaf blocks of a tree (its last level's words) with their block coordinates and
// the rank of their first voxel, plus a hash from block coordinates to block index:
// what a neighbour lookup needs without walking the tree from the root.
#pragma once

#include <cstdint>
#include <vector>

#include "block_hash.hpp"
#include "vola/tree.hpp"

namespace vola::analysis::detail {

struct LeafBlock {
  std::uint32_t bx, by, bz;  // block coordinates (voxel coordinates / 4)
  std::uint64_t word;        // occupancy
  std::uint64_t rank_base;   // rank of the block's first voxel
};

class LeafBlocks {
 public:
  explicit LeafBlocks(const Tree& tree);
  const std::vector<LeafBlock>& blocks() const noexcept { return blocks_; }
  // Index of the block at (bx, by, bz) (signed: neighbours may lie outside the grid),
  // or -1 when there is none.
  std::int64_t find(std::int64_t bx, std::int64_t by, std::int64_t bz) const noexcept {
    if (bx < 0 || by < 0 || bz < 0) return -1;
    const std::uint64_t* v = index_.find(pack_block(bx, by, bz));
    return v ? static_cast<std::int64_t>(*v) : -1;
  }

 private:
  std::vector<LeafBlock> blocks_;
  BlockHash index_;
};

}  // namespace vola::analysis::detail
