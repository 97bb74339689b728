// vola's map against OctoMap's OcTree after the same scans: for every voxel either one
// knows, whether the other knows it, the log-odds and the occupied/free decision.
#pragma once

#include <cstdint>
#include <string>

#include <octomap/OcTree.h>

#include "vola/map/occupancy_map.hpp"

namespace vola_map_test {

struct Agreement {
  std::uint64_t vola_voxels = 0, octomap_voxels = 0;
  std::uint64_t both = 0;             // known to both
  std::uint64_t only_vola = 0, only_octomap = 0;
  std::uint64_t same_log_odds = 0;    // of `both`, within 1e-5
  std::uint64_t same_decision = 0;    // of `both`
  double decision_fraction() const;   // same decision over voxels known to either
  std::string summary() const;
};

// OctoMap's key of vola's voxel (i, j, k): i + 32768 (tree depth 16).
octomap::OcTreeKey octomap_key(const vola::map::VoxelIndex& v);

Agreement compare(const vola::map::OccupancyMap& map, const octomap::OcTree& tree);

}  // namespace vola_map_test
