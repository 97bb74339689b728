// The obviously right occupancy model, for scenes whose coordinates are integers in
// units of 1/64 m and whose voxels are 16 units (0.25 m): a voxel is passed when the
// segment spends a positive length inside it, decided for every voxel of the segment's
// box by exact integer slab tests (no traversal, no floating point), plus the origin's
// voxel; then OctoMap's batch rules and float log-odds arithmetic.
#pragma once

#include <array>
#include <cstdint>
#include <map>
#include <vector>

#include "vola/map/occupancy_map.hpp"

namespace vola_map_test {

using Units = std::array<std::int64_t, 3>;  // a point in 1/64 m
inline constexpr std::int64_t kUnitsPerMetre = 64;
inline constexpr std::int64_t kVoxelUnits = 16;
inline constexpr double kVoxelSize = 0.25;

struct UnitScan {
  Units origin{};
  std::vector<Units> points;
};

class ReferenceMap {
 public:
  void insert(const UnitScan& scan);
  const std::map<vola::map::VoxelIndex, float>& cells() const { return cells_; }

  // The voxels the segment origin -> end passes (origin's included, end's excluded).
  static std::vector<vola::map::VoxelIndex> passed(const Units& origin, const Units& end);

 private:
  vola::map::SensorModel model_;
  std::map<vola::map::VoxelIndex, float> cells_;
};

// The scan as world coordinates in metres (exact: dyadic).
std::vector<double> metres(const std::vector<Units>& points);
vola::Point metres(const Units& p);

}  // namespace vola_map_test
