// The map's voxels of one state as a VOLA tree: the builder's grid quantization puts each
// voxel centre back into its own voxel, so indices, attributes and the file's frame come
// from the one road every tree takes.
#include <algorithm>

#include "vola/builder.hpp"
#include "vola/map/occupancy_map.hpp"

namespace vola::map {

Tree freeze(const OccupancyMap& map, VoxelState state) {
  const double size = map.voxel_size();
  PointCloud cloud;
  PointAttribute column{"log_odds", ValueType::f32, Reduction::last, {}};
  VoxelIndex lowest{kIndexLimit, kIndexLimit, kIndexLimit};
  for (const auto& [v, value] : map.voxels()) {
    if (map.occupied(value) != (state == VoxelState::occupied)) continue;
    // Centres, not corners: a corner can round to the voxel below in (x - origin) / R.
    cloud.xyz.insert(cloud.xyz.end(), {(v.i + 0.5) * size, (v.j + 0.5) * size, (v.k + 0.5) * size});
    column.values.push_back(value);
    lowest = {std::min(lowest.i, v.i), std::min(lowest.j, v.j), std::min(lowest.k, v.k)};
  }
  if (cloud.size() == 0) lowest = {0, 0, 0};
  cloud.attributes.push_back(std::move(column));
  BuildOptions options;
  options.quantization = Quantization::grid;
  options.voxel_size = size;
  // A multiple of R: the tree's voxel (0,0,0) is the map's lowest voxel.
  options.origin = Point{lowest.i * size, lowest.j * size, lowest.k * size};
  return build(cloud, options);
}

}  // namespace vola::map
