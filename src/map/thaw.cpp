// A state map back into the mutable map it was frozen from (vola/map/state_map.hpp):
// every known voxel (key order, so rank order for the log-odds column) restored at its
// map index, the tree's voxel plus the origin in whole voxels.
#include <array>
#include <cmath>
#include <string>

#include "vola/error.hpp"
#include "vola/map/occupancy_map.hpp"
#include "vola/map/state_map.hpp"

namespace vola::map {

OccupancyMap thaw(const Tree& state_map) {
  if (!is_state_map(state_map)) throw InvalidArgument("not a state map (vola map writes them)");
  const Frame frame = state_map.frame();
  const AttributeColumn* log_odds = state_map.attributes().find("log_odds");
  if (frame.quantization != Quantization::grid || !log_odds)
    throw InvalidArgument("a state map to insert into needs grid quantization and a log_odds column (vola map writes both)");
  const double size = frame.voxel_size;
  std::array<std::int64_t, 3> base{};
  for (int a = 0; a < 3; ++a) {
    const double cells = frame.origin[a] / size;
    base[a] = std::llround(cells);
    // freeze writes origin = index * R; anything else would move voxels off the map's lattice.
    if (!(std::abs(cells - static_cast<double>(base[a])) < 1e-6))
      throw InvalidArgument("the state map's origin is not a whole number of voxels of " + std::to_string(size));
  }
  OccupancyMap map(size);
  std::uint64_t rank = 0;
  state_map.for_each_voxel([&](const Voxel& v) {
    map.restore({static_cast<std::int32_t>(base[0] + v.x), static_cast<std::int32_t>(base[1] + v.y),
                 static_cast<std::int32_t>(base[2] + v.z)},
                static_cast<float>(log_odds->get(rank++)));
  });
  return map;
}

}  // namespace vola::map
