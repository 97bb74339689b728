// State-map queries and the plain trees of its occupied or free voxels
// (vola/map/state_map.hpp).
#include "vola/map/state_map.hpp"

#include <algorithm>
#include <bit>
#include <cstring>
#include <vector>

#include "vola/builder.hpp"
#include "vola/error.hpp"
#include "vola/setops.hpp"

namespace vola::map {

namespace {

void require_state_map(const Tree& tree, const char* what) {
  if (!is_state_map(tree))
    throw InvalidArgument(std::string(what) + ": the tree is not an occupancy-state map (vola map writes one)");
}

// The voxels of a state map whose state bit equals `occupied`, as a plain tree with the
// columns' rows of those voxels. One pass over the leaf blocks in storage (= key) order,
// so the wanted voxels' keys come out sorted and each block's first rank is a running sum.
Tree subset(const Tree& tree, bool occupied) {
  const int leaf = tree.depth() - 1;
  const auto states = tree.payload(leaf);
  std::vector<Key> keys;
  std::vector<std::uint64_t> rows;
  std::uint64_t rank = 0;
  tree.for_each_block(leaf, [&](std::size_t block, std::uint64_t word, std::uint32_t ox, std::uint32_t oy,
                                std::uint32_t oz) {
    const std::uint64_t state = states[block] & word;
    std::uint64_t wanted = occupied ? state : word & ~state;
    // The block's cells differ only in the key's lowest digit.
    const Key base = encode(ox, oy, oz);
    while (wanted) {
      const unsigned b = static_cast<unsigned>(std::countr_zero(wanted));
      wanted &= wanted - 1;
      keys.push_back(base | b);
      rows.push_back(rank + static_cast<std::uint64_t>(std::popcount(word & ((std::uint64_t{1} << b) - 1))));
    }
    rank += static_cast<std::uint64_t>(std::popcount(word));
  });
  Tree out = build_from_sorted_keys(keys, tree.depth());
  out.georef() = tree.georef();
  if (tree.stored_frame()) out.set_frame(*tree.stored_frame());
  for (const AttributeColumn& column : tree.attributes().columns()) {
    const std::size_t width = size_of(column.type());
    AttributeColumn kept(column.name(), column.type(), column.reduction(), rows.size());
    const std::byte* from = column.bytes().data();
    std::byte* to = kept.bytes().data();
    for (std::size_t n = 0; n < rows.size(); ++n) std::memcpy(to + n * width, from + rows[n] * width, width);
    out.attributes().add(std::move(kept));
  }
  return out;
}

}  // namespace

const char* name_of(VoxelState state) noexcept {
  switch (state) {
    case VoxelState::occupied: return "occupied";
    case VoxelState::free: return "free";
    case VoxelState::unknown: return "unknown";
  }
  return "unknown";
}

VoxelState state_at(const Tree& tree, const Voxel& v) noexcept {
  if (!is_state_map(tree)) return tree.contains(v) ? VoxelState::occupied : VoxelState::free;
  const auto word = tree.block_payload(v);
  if (!word) return VoxelState::unknown;
  return (*word >> bit_index(v.x & 3u, v.y & 3u, v.z & 3u)) & 1u ? VoxelState::occupied : VoxelState::free;
}

StateLookup::StateLookup(const Tree& tree)
    : tree_(tree), quantizer_(tree.quantizer()), log_odds_(tree.attributes().find("log_odds")) {}

WorldState StateLookup::at(const Point& p) const noexcept {
  Voxel v;
  if (!quantizer_.to_voxel(p, v)) return {is_state_map(tree_) ? VoxelState::unknown : VoxelState::free, {}};
  WorldState out{state_at(tree_, v), {}};
  if (log_odds_ && out.state != VoxelState::unknown)
    if (const auto rank = tree_.rank(v)) out.log_odds = static_cast<float>(log_odds_->get(*rank));
  return out;
}

Tree occupied_tree(const Tree& state_map) {
  if (!is_state_map(state_map)) return state_map;
  return subset(state_map, true);
}

Tree free_tree(const Tree& state_map) {
  require_state_map(state_map, "free_tree");
  return subset(state_map, false);
}

Tree free_at_depth(const Tree& free, const Tree& occupied_at_depth, int depth) {
  if (depth <= 0 || depth >= free.depth()) return free;
  return subtract(free.level_of_detail(depth), occupied_at_depth);
}

StateCounts state_counts(const Tree& state_map) {
  require_state_map(state_map, "state_counts");
  StateCounts c;
  const int leaf = state_map.depth() - 1;
  const auto states = state_map.payload(leaf);
  Voxel lo{~0u, ~0u, ~0u}, hi{0, 0, 0};
  state_map.for_each_block(leaf, [&](std::size_t block, std::uint64_t word, std::uint32_t ox, std::uint32_t oy,
                                     std::uint32_t oz) {
    const std::uint64_t state = states[block] & word;
    c.occupied += static_cast<std::uint64_t>(std::popcount(state));
    c.free += static_cast<std::uint64_t>(std::popcount(word & ~state));
    for (std::uint64_t w = word; w; w &= w - 1) {
      const unsigned b = static_cast<unsigned>(std::countr_zero(w));
      const Voxel v{ox + (b & 3u), oy + ((b >> 2) & 3u), oz + (b >> 4)};
      lo = {std::min(lo.x, v.x), std::min(lo.y, v.y), std::min(lo.z, v.z)};
      hi = {std::max(hi.x, v.x), std::max(hi.y, v.y), std::max(hi.z, v.z)};
    }
  });
  if (c.occupied + c.free == 0) return c;
  c.min = lo;
  c.max = hi;
  const std::uint64_t box = std::uint64_t{hi.x - lo.x + 1} * (hi.y - lo.y + 1) * (hi.z - lo.z + 1);
  c.unknown_in_bounds = box - (c.occupied + c.free);
  return c;
}

}  // namespace vola::map
