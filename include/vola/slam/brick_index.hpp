// A mutable VOLA-style occupancy index over brick coordinates: levels of nodes, each one
// 64-bit word for a 4x4x4 block of cells (bit i = x + 4 y + 16 z of the cell's local
// position, as in a .vol file), its children stored in the rank order of the set bits,
// so the child of bit i is children[popcount(word & ((1 << i) - 1))]. Unlike vola::Tree
// it takes insertions: a new child is inserted at its rank (at most 64 moves).
// to_tree() freezes it into a vola::Tree of the same cells.
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include "vola/tree.hpp"

namespace vola::slam {

class BrickIndex {
 public:
  // Cells 0 .. 4^levels - 1 per axis; levels in 1..10.
  explicit BrickIndex(int levels);
  int levels() const noexcept { return levels_; }
  std::uint32_t side() const noexcept { return 1u << (2 * levels_); }
  // The value stored for the cell, if present.
  std::optional<std::uint32_t> find(std::uint32_t x, std::uint32_t y, std::uint32_t z) const noexcept;
  // Stores value for a new cell (cells must be inside and not present yet).
  void insert(std::uint32_t x, std::uint32_t y, std::uint32_t z, std::uint32_t value);
  std::size_t size() const noexcept { return size_; }
  std::size_t memory_bytes() const noexcept;
  // The occupied cells as a frozen tree of depth levels().
  Tree to_tree() const;

 private:
  struct Node {
    std::uint64_t occupancy = 0;
    std::vector<std::uint32_t> children;  // node indices, or values on the last level
  };
  static unsigned bit_of(std::uint32_t x, std::uint32_t y, std::uint32_t z, int shift) noexcept {
    return ((x >> shift) & 3u) | ((y >> shift) & 3u) << 2 | ((z >> shift) & 3u) << 4;
  }
  int levels_;
  std::vector<Node> nodes_;  // nodes_[0] is the root
  std::size_t size_ = 0;
};

}  // namespace vola::slam
