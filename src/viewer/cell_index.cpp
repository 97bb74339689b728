#include "vola/viewer/cell_index.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <string>

#include "vola/error.hpp"

namespace vola::viewer {

namespace {

Voxel offset_of(const Voxel& origin, unsigned bit) noexcept {
  return Voxel{origin.x + (bit & 3u), origin.y + ((bit >> 2) & 3u), origin.z + (bit >> 4)};
}

// The position of the n-th (from 0) set bit of `word`; word has more than n set bits.
unsigned select_bit(std::uint64_t word, std::uint64_t n) noexcept {
  for (; n > 0; --n) word &= word - 1;
  return static_cast<unsigned>(std::countr_zero(word));
}

std::uint64_t bits_above(std::uint64_t word, unsigned bit) noexcept {
  return bit == 63 ? 0 : word & ~((std::uint64_t{2} << bit) - 1);
}

}  // namespace

CellIndex::CellIndex(const Tree& tree) : tree_(&tree), depth_(tree.depth()), prefix_(tree.depth()) {
  for (int l = 0; l < depth_; ++l) {
    const auto words = tree.occupancy(l);
    auto& prefix = prefix_[l];
    prefix.resize(words.size() + 1);
    std::uint64_t sum = 0;
    for (std::size_t b = 0; b < words.size(); ++b) {
      prefix[b] = sum;
      sum += static_cast<std::uint64_t>(std::popcount(words[b]));
    }
    prefix[words.size()] = sum;
  }
}

void CellIndex::check_level(int level) const {
  if (level < 0 || level >= depth_)
    throw InvalidArgument("level " + std::to_string(level) + " is outside 0.." + std::to_string(depth_ - 1));
}

std::size_t CellIndex::block_of(int level, std::uint64_t index, unsigned& bit) const noexcept {
  const auto& prefix = prefix_[level];
  // The last word whose running count is <= index: its bits hold cell `index`.
  const auto it = std::upper_bound(prefix.begin(), prefix.end() - 1, index) - 1;
  const auto block = static_cast<std::size_t>(it - prefix.begin());
  bit = select_bit(tree_->occupancy(level)[block], index - *it);
  return block;
}

Voxel CellIndex::cell(int level, std::uint64_t index) const {
  check_level(level);
  if (index >= cell_count(level))
    throw InvalidArgument("cell " + std::to_string(index) + " is past the " + std::to_string(cell_count(level)) +
                          " cells of level " + std::to_string(level));
  Voxel result{};
  for_each_cell(level, index, 1, [&](std::uint64_t, const Voxel& c) { result = c; });
  return result;
}

void CellIndex::for_each_cell(int level, std::uint64_t first, std::uint64_t count,
                              const std::function<void(std::uint64_t, const Voxel&)>& f) const {
  check_level(level);
  const std::uint64_t total = cell_count(level);
  if (first >= total || count == 0) return;
  const std::uint64_t end = first + std::min(count, total - first);

  // Per level from the root to `level`: the current block, the bits of its word not yet
  // visited, the block's origin and the current cell.
  std::array<std::size_t, kMaxDepth> block{};
  std::array<std::uint64_t, kMaxDepth> rest{};
  std::array<Voxel, kMaxDepth> origin{};
  std::array<Voxel, kMaxDepth> current{};
  std::array<unsigned, kMaxDepth> bit{};
  std::uint64_t index = first;
  for (int l = level; l >= 0; --l) {
    block[l] = block_of(l, index, bit[l]);
    index = block[l];  // block b of level l holds the children of cell b of level l-1
  }
  for (int l = 0; l <= level; ++l) {
    origin[l] = l == 0 ? Voxel{0, 0, 0} : Voxel{current[l - 1].x * 4, current[l - 1].y * 4, current[l - 1].z * 4};
    current[l] = offset_of(origin[l], bit[l]);
    rest[l] = bits_above(tree_->occupancy(l)[block[l]], bit[l]);
  }

  // Moves level l to its next cell, moving its parent on when its word is used up.
  auto advance = [&](int l, auto& self) -> void {
    if (rest[l] == 0) {
      self(l - 1, self);  // never past level 0: the caller stops at the level's last cell
      ++block[l];
      origin[l] = Voxel{current[l - 1].x * 4, current[l - 1].y * 4, current[l - 1].z * 4};
      rest[l] = tree_->occupancy(l)[block[l]];
    }
    const unsigned b = static_cast<unsigned>(std::countr_zero(rest[l]));
    rest[l] &= rest[l] - 1;
    current[l] = offset_of(origin[l], b);
  };
  for (std::uint64_t i = first;;) {
    f(i, current[level]);
    if (++i == end) break;
    advance(level, advance);
  }
}

std::uint64_t CellIndex::first_voxel_rank(int level, std::uint64_t index) const noexcept {
  // The first child of cell c of level l is the first cell of block c of level l+1.
  for (int l = level + 1; l < depth_; ++l) index = prefix_[l][index];
  return index;
}

}  // namespace vola::viewer
