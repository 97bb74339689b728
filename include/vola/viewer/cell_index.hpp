// Random access to the occupied cells of any level of a tree, in storage (key) order,
// for streaming a level in batches: cell i of level L is found by binary search over
// per-level running popcounts and walking up through its parents, and the cells after
// it by stepping along the words, so a batch costs O(depth log n) to start and O(1)
// per cell, whatever its offset.
//
// Cell i of level L is the i-th set bit of that level's words; block b of level L+1
// holds the children of cell b of level L. Every cell has at least one child (no block
// below the root is zero), so a cell's first voxel in key order is reached by following
// first children down.
#pragma once

#include <cstdint>
#include <functional>
#include <vector>

#include "vola/key.hpp"
#include "vola/tree.hpp"

namespace vola::viewer {

class CellIndex {
 public:
  // The tree must outlive the index. Costs one pass over the words and 8 bytes per word.
  explicit CellIndex(const Tree& tree);

  int depth() const noexcept { return depth_; }
  std::uint64_t cell_count(int level) const noexcept { return prefix_[level].back(); }

  // Calls f(index, cell) for cells [first, first + count) of `level` (clipped to the
  // level's cell count), cell coordinates on the level's 4^(level+1) grid.
  // Throws InvalidArgument for a level outside 0..depth-1.
  void for_each_cell(int level, std::uint64_t first, std::uint64_t count,
                     const std::function<void(std::uint64_t, const Voxel&)>& f) const;
  // The coordinates of cell `index` of `level` (index < cell_count(level)).
  Voxel cell(int level, std::uint64_t index) const;
  // The rank (index among all voxels in key order) of the first voxel inside cell
  // `index` of `level`: the voxel whose attributes stand for the cell.
  std::uint64_t first_voxel_rank(int level, std::uint64_t index) const noexcept;

 private:
  void check_level(int level) const;
  // The block of `level` holding cell `index`, and the bit of that cell in its word.
  std::size_t block_of(int level, std::uint64_t index, unsigned& bit) const noexcept;

  const Tree* tree_;
  int depth_;
  // prefix_[l][b] = set bits in level l's words before word b (size words + 1).
  std::vector<std::vector<std::uint64_t>> prefix_;
};

}  // namespace vola::viewer
