// A voxel set as bricks: one 64-bit word per occupied 4x4x4 block (bit x + 4y + 16z),
// keyed by block coordinates in a hash. Shifting a set by a voxel offset is a shift of
// each word plus the bits carried into neighbouring bricks, so morphology runs 64
// voxels at a time and only where voxels are.
#pragma once

#include <cstdint>

#include "block_hash.hpp"
#include "vola/tree.hpp"

namespace vola::analysis::detail {

class BrickSet {
 public:
  // An empty set on the grid of a depth-`depth` tree.
  explicit BrickSet(int depth, std::size_t expected_blocks = 0);
  static BrickSet from_tree(const Tree& tree);

  int depth() const noexcept { return depth_; }
  std::size_t blocks() const noexcept { return bricks_.size(); }
  // ORs `word` into the brick at (bx, by, bz); bricks outside the grid are dropped.
  void add(std::int64_t bx, std::int64_t by, std::int64_t bz, std::uint64_t word) {
    if (word == 0 || bx < 0 || by < 0 || bz < 0 || bx >= blocks_per_axis_ || by >= blocks_per_axis_ ||
        bz >= blocks_per_axis_)
      return;
    bricks_.at(pack_block(bx, by, bz)) |= word;
  }
  std::uint64_t get(std::int64_t bx, std::int64_t by, std::int64_t bz) const noexcept {
    if (bx < 0 || by < 0 || bz < 0) return 0;
    const std::uint64_t* w = bricks_.find(pack_block(bx, by, bz));
    return w ? *w : 0;
  }
  // f(bx, by, bz, word) for every brick (words may be zero after masking).
  template <class F>
  void for_each(F&& f) const {
    bricks_.for_each([&](std::uint64_t key, std::uint64_t word) { f(block_x(key), block_y(key), block_z(key), word); });
  }
  // ORs `other` shifted by (dx, dy, dz) voxels into this set.
  void add_shifted(const BrickSet& other, int dx, int dy, int dz);
  // The set as a tree of its depth (no frame: the caller copies the source's).
  Tree to_tree() const;

 private:
  int depth_;
  std::int64_t blocks_per_axis_;
  BlockHash bricks_;
};

}  // namespace vola::analysis::detail
