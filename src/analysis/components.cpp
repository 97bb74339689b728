// Union-find over voxel ranks. Each voxel is joined with its already-visited ("backward")
// neighbours; a neighbour is found in the voxel's own 4x4x4 word or in one of the 26
// neighbouring words, whose indices are looked up once per block.
#include "vola/analysis/components.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <limits>
#include <numeric>

#include "leaf_blocks.hpp"
#include "vola/error.hpp"

namespace vola::analysis {

Connectivity parse_connectivity(int neighbours) {
  switch (neighbours) {
    case 6: return Connectivity::faces;
    case 18: return Connectivity::edges;
    case 26: return Connectivity::corners;
    default: throw InvalidArgument("connectivity must be 6, 18 or 26, not " + std::to_string(neighbours));
  }
}

namespace {

struct Offset {
  int dx, dy, dz;
};

// Half of the neighbourhood: the offsets that come before (0,0,0) in z, y, x order, so
// that every neighbouring pair is joined exactly once.
std::vector<Offset> backward_offsets(Connectivity c) {
  std::vector<Offset> out;
  const int limit = c == Connectivity::faces ? 1 : c == Connectivity::edges ? 2 : 3;
  for (int dz = -1; dz <= 1; ++dz)
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        const int nonzero = (dx != 0) + (dy != 0) + (dz != 0);
        if (nonzero == 0 || nonzero > limit) continue;
        if (dz * 9 + dy * 3 + dx < 0) out.push_back({dx, dy, dz});
      }
  return out;
}

class UnionFind {
 public:
  explicit UnionFind(std::size_t n) : parent_(n) { std::iota(parent_.begin(), parent_.end(), std::uint32_t{0}); }
  std::uint32_t find(std::uint32_t i) noexcept {
    while (parent_[i] != i) {
      parent_[i] = parent_[parent_[i]];  // path halving
      i = parent_[i];
    }
    return i;
  }
  // The smaller index becomes the root: a root is its component's first voxel.
  void join(std::uint32_t a, std::uint32_t b) noexcept {
    a = find(a);
    b = find(b);
    if (a == b) return;
    if (a < b) parent_[b] = a;
    else parent_[a] = b;
  }
  std::vector<std::uint32_t>& parents() noexcept { return parent_; }

 private:
  std::vector<std::uint32_t> parent_;
};

// Joins every voxel with its occupied backward neighbours (the offsets), block by block.
void join_neighbours(const detail::LeafBlocks& leaves, const std::vector<Offset>& offsets, UnionFind& sets) {
  const auto& blocks = leaves.blocks();
  for (const detail::LeafBlock& block : blocks) {
    // Neighbouring block indices by (dx+1) + 3(dy+1) + 9(dz+1); resolved on first use.
    std::array<std::int64_t, 27> near;
    near.fill(-2);
    near[13] = &block - blocks.data();
    std::uint64_t word = block.word;
    while (word) {
      const unsigned bit = static_cast<unsigned>(std::countr_zero(word));
      word &= word - 1;
      const int lx = bit & 3, ly = (bit >> 2) & 3, lz = bit >> 4;
      const auto self = static_cast<std::uint32_t>(
          block.rank_base + static_cast<std::uint64_t>(std::popcount(block.word & ((std::uint64_t{1} << bit) - 1))));
      for (const Offset& o : offsets) {
        const int nx = lx + o.dx, ny = ly + o.dy, nz = lz + o.dz;
        const int cx = nx < 0 ? -1 : nx > 3 ? 1 : 0;
        const int cy = ny < 0 ? -1 : ny > 3 ? 1 : 0;
        const int cz = nz < 0 ? -1 : nz > 3 ? 1 : 0;
        const int slot = (cx + 1) + 3 * (cy + 1) + 9 * (cz + 1);
        if (near[slot] == -2)
          near[slot] = leaves.find(std::int64_t{block.bx} + cx, std::int64_t{block.by} + cy, std::int64_t{block.bz} + cz);
        if (near[slot] < 0) continue;
        const detail::LeafBlock& other = blocks[static_cast<std::size_t>(near[slot])];
        const unsigned nbit = static_cast<unsigned>((nx & 3) + 4 * (ny & 3) + 16 * (nz & 3));
        if (!((other.word >> nbit) & 1u)) continue;
        const auto neighbour = static_cast<std::uint32_t>(
            other.rank_base + static_cast<std::uint64_t>(std::popcount(other.word & ((std::uint64_t{1} << nbit) - 1))));
        sets.join(self, neighbour);
      }
    }
  }
}

// The components in order of their first voxel, with sizes, boxes and coordinate sums;
// `label` (the union-find parents) becomes each voxel's index into them. Roots are first
// voxels: walking ranks upward, every parent (a smaller rank) has already been
// overwritten with its component's number, so one lookup gives a voxel's number.
std::vector<Component> number_components(const detail::LeafBlocks& leaves, std::vector<std::uint32_t>& label,
                                         std::vector<std::array<double, 3>>& sums) {
  std::vector<Component> found;
  std::uint64_t rank = 0;
  for (const detail::LeafBlock& block : leaves.blocks()) {
    std::uint64_t word = block.word;
    while (word) {
      const unsigned bit = static_cast<unsigned>(std::countr_zero(word));
      word &= word - 1;
      const Voxel v{block.bx * 4 + (bit & 3u), block.by * 4 + ((bit >> 2) & 3u), block.bz * 4 + (bit >> 4)};
      std::uint32_t id;
      if (label[rank] == rank) {
        id = static_cast<std::uint32_t>(found.size());
        found.push_back({0, v, v, {0, 0, 0}, rank});
        sums.push_back({0, 0, 0});
      } else {
        id = label[label[rank]];
      }
      label[rank] = id;
      Component& c = found[id];
      ++c.voxels;
      c.min = {std::min(c.min.x, v.x), std::min(c.min.y, v.y), std::min(c.min.z, v.z)};
      c.max = {std::max(c.max.x, v.x), std::max(c.max.y, v.y), std::max(c.max.z, v.z)};
      sums[id][0] += v.x;
      sums[id][1] += v.y;
      sums[id][2] += v.z;
      ++rank;
    }
  }
  return found;
}

}  // namespace

ComponentLabels label_components(const Tree& tree, Connectivity connectivity) {
  ComponentLabels out;
  const std::uint64_t n = tree.voxel_count();
  if (n > std::numeric_limits<std::uint32_t>::max())
    throw InvalidArgument("connected components: more than 2^32 - 1 voxels");
  if (n == 0) return out;

  const detail::LeafBlocks leaves(tree);
  UnionFind sets(static_cast<std::size_t>(n));
  join_neighbours(leaves, backward_offsets(connectivity), sets);
  std::vector<std::uint32_t>& label = sets.parents();
  std::vector<std::array<double, 3>> sums;
  const std::vector<Component> found = number_components(leaves, label, sums);

  // Order: largest first, ties by first voxel (found is already in first-voxel order).
  std::vector<std::uint32_t> order(found.size());
  std::iota(order.begin(), order.end(), std::uint32_t{0});
  std::stable_sort(order.begin(), order.end(),
                   [&](std::uint32_t a, std::uint32_t b) { return found[a].voxels > found[b].voxels; });
  std::vector<std::uint32_t> final_id(found.size());
  out.components.reserve(found.size());
  for (std::uint32_t i = 0; i < order.size(); ++i) {
    final_id[order[i]] = i;
    Component c = found[order[i]];
    for (int a = 0; a < 3; ++a) c.centroid[a] = sums[order[i]][a] / static_cast<double>(c.voxels);
    out.components.push_back(c);
  }
  for (std::uint32_t& l : label) l = final_id[l];
  out.label = std::move(label);
  return out;
}

}  // namespace vola::analysis
