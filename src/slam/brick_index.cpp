#include "vola/slam/brick_index.hpp"

#include <bit>

#include "vola/builder.hpp"
#include "vola/error.hpp"

namespace vola::slam {

BrickIndex::BrickIndex(int levels) : levels_(levels) {
  if (levels < 1 || levels > 10) throw InvalidArgument("brick index: levels must be 1..10");
  nodes_.emplace_back();
}

std::optional<std::uint32_t> BrickIndex::find(std::uint32_t x, std::uint32_t y, std::uint32_t z) const noexcept {
  if (((x | y | z) >> (2 * levels_)) != 0) return std::nullopt;
  const Node* node = &nodes_[0];
  for (int l = 0;; ++l) {
    const unsigned bit = bit_of(x, y, z, 2 * (levels_ - 1 - l));
    if (!((node->occupancy >> bit) & 1u)) return std::nullopt;
    const std::uint32_t child =
        node->children[static_cast<std::size_t>(std::popcount(node->occupancy & ((std::uint64_t{1} << bit) - 1)))];
    if (l == levels_ - 1) return child;
    node = &nodes_[child];
  }
}

void BrickIndex::insert(std::uint32_t x, std::uint32_t y, std::uint32_t z, std::uint32_t value) {
  if (((x | y | z) >> (2 * levels_)) != 0) throw InvalidArgument("brick index: cell outside the index");
  std::size_t node = 0;
  for (int l = 0;; ++l) {
    const unsigned bit = bit_of(x, y, z, 2 * (levels_ - 1 - l));
    const std::uint64_t mask = std::uint64_t{1} << bit;
    const auto rank = static_cast<std::size_t>(std::popcount(nodes_[node].occupancy & (mask - 1)));
    const bool present = (nodes_[node].occupancy & mask) != 0;
    if (l == levels_ - 1) {
      if (present) throw InvalidArgument("brick index: cell already present");
      nodes_[node].occupancy |= mask;
      nodes_[node].children.insert(nodes_[node].children.begin() + static_cast<std::ptrdiff_t>(rank), value);
      ++size_;
      return;
    }
    if (!present) {
      const auto created = static_cast<std::uint32_t>(nodes_.size());
      nodes_.emplace_back();  // may move nodes_: index, never hold references across it
      nodes_[node].occupancy |= mask;
      nodes_[node].children.insert(nodes_[node].children.begin() + static_cast<std::ptrdiff_t>(rank), created);
    }
    node = nodes_[node].children[rank];
  }
}

std::size_t BrickIndex::memory_bytes() const noexcept {
  std::size_t bytes = nodes_.capacity() * sizeof(Node);
  for (const auto& n : nodes_) bytes += n.children.capacity() * sizeof(std::uint32_t);
  return bytes;
}

Tree BrickIndex::to_tree() const {
  std::vector<Voxel> cells;
  cells.reserve(size_);
  // Depth-first over the nodes, rebuilding each cell's coordinates from the path.
  struct Frame {
    std::uint32_t node;
    int level;
    std::uint32_t x, y, z;
  };
  std::vector<Frame> stack{{0, 0, 0, 0, 0}};
  while (!stack.empty()) {
    const Frame f = stack.back();
    stack.pop_back();
    const Node& n = nodes_[f.node];
    std::uint64_t word = n.occupancy;
    std::size_t rank = 0;
    while (word) {
      const auto bit = static_cast<unsigned>(std::countr_zero(word));
      word &= word - 1;
      const std::uint32_t x = f.x * 4 + (bit & 3u), y = f.y * 4 + ((bit >> 2) & 3u), z = f.z * 4 + (bit >> 4);
      if (f.level == levels_ - 1)
        cells.push_back({x, y, z});
      else
        stack.push_back({n.children[rank], f.level + 1, x, y, z});
      ++rank;
    }
  }
  return build_from_voxels(cells, levels_);
}

}  // namespace vola::slam
