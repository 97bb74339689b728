// Shared by the map tests (OctoMap, OpenVDB): occupancy maps as `vola map` freezes them
// (grid quantization, origin a multiple of the voxel size, a log_odds column), random
// voxels in world cells, and the world cell of a tree's voxel.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <map>
#include <random>
#include <set>

#include "test_support.hpp"

namespace vola_map_test {

// A world cell: floor(x / R) per axis, the index OctoMap's key is 32768 above.
using Cell = std::array<std::int64_t, 3>;

// OctoMap's default clamping, as it stores it: the float of log(p / (1 - p)).
inline const float kClampMax = static_cast<float>(std::log(0.971 / (1 - 0.971)));
inline const float kClampMin = static_cast<float>(std::log(0.1192 / (1 - 0.1192)));

struct RandomMap {
  double voxel_size = 0.1;
  std::map<Cell, float> occupied;  // cell -> log-odds (>= 0, OctoMap's occupied)
  std::map<Cell, float> free;      // cell -> log-odds (< 0), disjoint from occupied
};

// Clusters of cells within +-span of a random centre, log-odds within OctoMap's clamping
// (half of them at its limits, so that pruning merges whole octants in the files).
RandomMap random_map(std::uint64_t seed, double voxel_size, std::int64_t span, std::size_t count);

// The cells of one state as a tree on the grid `vola map` would use: origin = the lowest
// cell * R (a multiple of R), centres built back into their cells, a log_odds column
// (f32) unless `log_odds` is false.
vola::Tree tree_of(const std::map<Cell, float>& cells, double voxel_size, bool log_odds);
// Each voxel's world cell, from the tree's frame (origin a whole number of voxels).
std::map<Cell, float> cells_of(const vola::Tree& tree);

}  // namespace vola_map_test
