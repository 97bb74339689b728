#include "brick_set.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <utility>
#include <vector>

#include "vola/builder.hpp"

namespace vola::analysis::detail {

namespace {

// Bits whose coordinate along `axis` (0 = x, 1 = y, 2 = z) is at least s (0..3).
constexpr std::uint64_t at_least(int axis, int s) noexcept {
  std::uint64_t m = 0;
  for (unsigned b = 0; b < 64; ++b) {
    const unsigned c = axis == 0 ? (b & 3u) : axis == 1 ? ((b >> 2) & 3u) : (b >> 4);
    if (static_cast<int>(c) >= s) m |= std::uint64_t{1} << b;
  }
  return m;
}
constexpr std::array<std::array<std::uint64_t, 4>, 3> kAtLeast = {{
    {at_least(0, 0), at_least(0, 1), at_least(0, 2), at_least(0, 3)},
    {at_least(1, 0), at_least(1, 1), at_least(1, 2), at_least(1, 3)},
    {at_least(2, 0), at_least(2, 1), at_least(2, 2), at_least(2, 3)},
}};
constexpr unsigned kStride[3] = {1, 4, 16};

// A word shifted by s in 0..3 voxels along `axis`: the part that stays in its brick
// and the part carried into the next brick.
std::pair<std::uint64_t, std::uint64_t> shift_word(std::uint64_t w, int axis, int s) noexcept {
  if (s == 0) return {w, 0};
  const unsigned t = kStride[axis];
  return {(w << (s * t)) & kAtLeast[axis][s], (w >> ((4 - s) * t)) & ~kAtLeast[axis][s]};
}

// floor(d / 4) and d - 4 * floor(d / 4).
std::pair<int, int> split(int d) noexcept {
  const int q = d >= 0 ? d / 4 : -((-d + 3) / 4);
  return {q, d - 4 * q};
}

}  // namespace

BrickSet::BrickSet(int depth, std::size_t expected_blocks)
    : depth_(depth), blocks_per_axis_(std::int64_t{side_of(depth)} / 4), bricks_(expected_blocks) {}

BrickSet BrickSet::from_tree(const Tree& tree) {
  BrickSet set(tree.depth(), tree.occupancy(tree.depth() - 1).size());
  if (tree.empty()) return set;
  tree.for_each_block(tree.depth() - 1, [&](std::size_t, std::uint64_t word, std::uint32_t ox, std::uint32_t oy,
                                            std::uint32_t oz) { set.add(ox / 4, oy / 4, oz / 4, word); });
  return set;
}

void BrickSet::add_shifted(const BrickSet& other, int dx, int dy, int dz) {
  const auto [qx, sx] = split(dx);
  const auto [qy, sy] = split(dy);
  const auto [qz, sz] = split(dz);
  other.for_each([&](std::int64_t bx, std::int64_t by, std::int64_t bz, std::uint64_t w) {
    const auto x = shift_word(w, 0, sx);
    for (int i = 0; i < 2; ++i) {
      const std::uint64_t wx = i ? x.second : x.first;
      if (!wx) continue;
      const auto y = shift_word(wx, 1, sy);
      for (int j = 0; j < 2; ++j) {
        const std::uint64_t wy = j ? y.second : y.first;
        if (!wy) continue;
        const auto z = shift_word(wy, 2, sz);
        add(bx + qx + i, by + qy + j, bz + qz, z.first);
        add(bx + qx + i, by + qy + j, bz + qz + 1, z.second);
      }
    }
  });
}

// The bricks are the tree's leaf words: the levels above them are the tree of depth - 1
// over the block coordinates, so the set never expands into one key per voxel (8 bytes
// a voxel, by far the largest allocation of a dilation otherwise).
Tree BrickSet::to_tree() const {
  std::vector<std::pair<Key, std::uint64_t>> sorted;
  sorted.reserve(bricks_.size());
  for_each([&](std::uint32_t bx, std::uint32_t by, std::uint32_t bz, std::uint64_t word) {
    if (word) sorted.emplace_back(encode(bx, by, bz), word);
  });
  if (sorted.empty()) return build_from_sorted_keys({}, depth_);
  std::sort(sorted.begin(), sorted.end());
  std::vector<std::uint64_t> words;
  if (depth_ > 1) {
    std::vector<Key> blocks;
    blocks.reserve(sorted.size());
    for (const auto& entry : sorted) blocks.push_back(entry.first);
    const Tree upper = build_from_sorted_keys(blocks, depth_ - 1);
    for (int level = 0; level < upper.depth(); ++level) {
      const auto occupancy = upper.occupancy(level);
      words.insert(words.end(), occupancy.begin(), occupancy.end());
    }
  }
  // Leaf words in key order: the order of the set bits of the level above.
  for (const auto& entry : sorted) words.push_back(entry.second);
  return Tree::from_levels(depth_, false, std::move(words));
}

}  // namespace vola::analysis::detail
