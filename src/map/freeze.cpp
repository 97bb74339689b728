// The map frozen into a state map (vola/map/state_map.hpp): the known voxels' keys are
// radix-sorted once, the occupancy levels come from the bulk builder, and every level's
// state words from one pass over the sorted keys.
#include <algorithm>
#include <array>
#include <cmath>
#include <span>
#include <string>
#include <vector>

#include "vola/builder.hpp"
#include "vola/error.hpp"
#include "vola/map/occupancy_map.hpp"
#include "vola/map/state_map.hpp"

namespace vola::map {

namespace {

struct Bounds {
  VoxelIndex lo{kIndexLimit, kIndexLimit, kIndexLimit};
  VoxelIndex hi{-kIndexLimit, -kIndexLimit, -kIndexLimit};
};

// The smallest depth whose grid holds `span` voxels per axis.
int depth_for(std::int64_t span) {
  for (int depth = kMinDepth; depth <= kMaxDepth; ++depth)
    if (span <= std::int64_t{side_of(depth)}) return depth;
  throw InvalidArgument("the map's known voxels span " + std::to_string(span) + " voxels on an axis; a VOLA tree holds " +
                        std::to_string(side_of(kMaxDepth)) + " at most (depth " + std::to_string(kMaxDepth) + ")");
}

// State words for every level, block for block with the occupancy words: bit b of a
// block's word is set when cell b holds an occupied voxel. Blocks of a level are stored in
// key order, so a block index advances whenever the key's prefix above that level changes.
std::vector<std::vector<std::uint64_t>> state_words(const Tree& occupancy, std::span<const Key> keys,
                                                    std::span<const std::uint8_t> occupied) {
  const int depth = occupancy.depth();
  std::vector<std::vector<std::uint64_t>> words(static_cast<std::size_t>(depth));
  for (int l = 0; l < depth; ++l) words[l].assign(occupancy.occupancy(l).size(), 0);
  std::array<std::size_t, kMaxDepth> block{};
  std::array<Key, kMaxDepth> prefix{};
  for (std::size_t n = 0; n < keys.size(); ++n) {
    for (int l = 0; l < depth; ++l) {
      const Key p = keys[n] >> (6 * (depth - l));
      if (n > 0 && p != prefix[l]) ++block[l];
      prefix[l] = p;
      if (occupied[n]) words[l][block[l]] |= std::uint64_t{1} << ((keys[n] >> (6 * (depth - 1 - l))) & 63u);
    }
  }
  return words;
}

// The state map of known voxels given by their keys (any order), log-odds and states:
// one radix sort, the bulk builder for the occupancy levels, one pass for the state words.
// Throws InvalidArgument naming a voxel given twice.
Tree assemble(std::vector<Key> keys, std::vector<float> values, std::vector<std::uint8_t> states, int depth,
              const Frame& frame) {
  std::vector<std::uint32_t> order(keys.size());
  for (std::size_t n = 0; n < order.size(); ++n) order[n] = static_cast<std::uint32_t>(n);
  radix_sort(keys, &order, 6 * depth);
  for (std::size_t n = 1; n < keys.size(); ++n)
    if (keys[n] == keys[n - 1]) {
      const Voxel v = decode(keys[n]);
      throw InvalidArgument("voxel (" + std::to_string(v.x) + ", " + std::to_string(v.y) + ", " + std::to_string(v.z) +
                            ") is given twice (as occupied and as free, or twice in one state)");
    }
  std::vector<std::uint8_t> occupied(keys.size());
  AttributeColumn column("log_odds", ValueType::f32, Reduction::last, keys.size());
  for (std::size_t n = 0; n < keys.size(); ++n) {
    occupied[n] = states[order[n]];
    column.set(n, values[order[n]]);  // a float through double: exact
  }
  values = {};
  states = {};
  order = {};

  const Tree occupancy = build_from_sorted_keys(keys, depth);
  const auto state_levels = state_words(occupancy, keys, occupied);
  std::vector<std::uint64_t> words;
  words.reserve(2 * occupancy.words().size());
  for (int l = 0; l < depth; ++l) {
    const auto level = occupancy.occupancy(l);
    words.insert(words.end(), level.begin(), level.end());
    words.insert(words.end(), state_levels[l].begin(), state_levels[l].end());
  }
  Tree tree = Tree::from_levels(depth, true, std::move(words));
  tree.set_nbits(1);
  tree.set_payload_meaning(PayloadMeaning::occupancy_state);
  tree.set_frame(frame);
  tree.attributes().add(std::move(column));
  return tree;
}

}  // namespace

Tree freeze(const OccupancyMap& map) {
  const double size = map.voxel_size();
  Bounds b;
  map.for_each([&](const VoxelIndex& v, float) {
    b.lo = {std::min(b.lo.i, v.i), std::min(b.lo.j, v.j), std::min(b.lo.k, v.k)};
    b.hi = {std::max(b.hi.i, v.i), std::max(b.hi.j, v.j), std::max(b.hi.k, v.k)};
  });
  if (map.size() == 0) b = {{0, 0, 0}, {0, 0, 0}};
  const int depth = depth_for(std::int64_t{1} + std::max({std::int64_t{b.hi.i} - b.lo.i,
                                                          std::int64_t{b.hi.j} - b.lo.j,
                                                          std::int64_t{b.hi.k} - b.lo.k}));
  std::vector<Key> keys;
  std::vector<float> values;
  std::vector<std::uint8_t> states;
  keys.reserve(map.size());
  values.reserve(map.size());
  states.reserve(map.size());
  map.for_each([&](const VoxelIndex& v, float value) {
    keys.push_back(encode(static_cast<std::uint32_t>(v.i - b.lo.i), static_cast<std::uint32_t>(v.j - b.lo.j),
                          static_cast<std::uint32_t>(v.k - b.lo.k)));
    values.push_back(value);
    states.push_back(map.occupied(value) ? 1 : 0);
  });
  // A multiple of R: the tree's voxel (0,0,0) is the map's lowest voxel.
  const Point origin{b.lo.i * size, b.lo.j * size, b.lo.k * size};
  Tree tree =
      assemble(std::move(keys), std::move(values), std::move(states), depth, Frame{Quantization::grid, origin, size});
  tree.georef().bbox = Box{origin, {(b.hi.i + 1) * size, (b.hi.j + 1) * size, (b.hi.k + 1) * size}};
  return tree;
}

Tree state_map_from_voxels(std::span<const Voxel> occupied, std::span<const float> occupied_log_odds,
                           std::span<const Voxel> free, std::span<const float> free_log_odds, int depth,
                           const Frame& frame) {
  if (depth < kMinDepth || depth > kMaxDepth)
    throw InvalidArgument("state map: depth " + std::to_string(depth) + " is not 1.." + std::to_string(kMaxDepth));
  const SensorModel model;
  const auto check = [&](const char* state, std::span<const Voxel> voxels, std::span<const float> log_odds) {
    if (!log_odds.empty() && log_odds.size() != voxels.size())
      throw InvalidArgument(std::string("state map: ") + std::to_string(log_odds.size()) + " log-odds for " +
                            std::to_string(voxels.size()) + " " + state + " voxels");
    for (const Voxel& v : voxels)
      if (std::max({v.x, v.y, v.z}) >= side_of(depth))
        throw InvalidArgument(std::string("state map: an ") + state + " voxel lies outside a depth-" +
                              std::to_string(depth) + " grid");
    for (float value : log_odds)
      if (!std::isfinite(value))
        throw InvalidArgument(std::string("state map: a log-odds of the ") + state + " voxels is not finite");
  };
  check("occupied", occupied, occupied_log_odds);
  check("free", free, free_log_odds);
  std::vector<Key> keys;
  std::vector<float> values;
  std::vector<std::uint8_t> states;
  const std::size_t known = occupied.size() + free.size();
  keys.reserve(known);
  values.reserve(known);
  states.reserve(known);
  for (std::size_t n = 0; n < occupied.size(); ++n) {
    keys.push_back(encode(occupied[n]));
    values.push_back(occupied_log_odds.empty() ? model.clamp_max : occupied_log_odds[n]);
    states.push_back(1);
  }
  for (std::size_t n = 0; n < free.size(); ++n) {
    keys.push_back(encode(free[n]));
    values.push_back(free_log_odds.empty() ? model.clamp_min : free_log_odds[n]);
    states.push_back(0);
  }
  return assemble(std::move(keys), std::move(values), std::move(states), depth, frame);
}

}  // namespace vola::map
