// Internal: the overview pyramid of a tile set. Level L tiles cover 4x4x4 tiles of
// level L-1 (level 0 = the tiles themselves) at the same depth; each voxel is one
// level-(depth-2) cell of a child, so level L voxels are 4^L tile voxels wide.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "vola/tile/communicator.hpp"
#include "tile_georef.hpp"
#include "vola/tile/tile_index.hpp"

namespace vola::tile {

struct OverviewContext {
  const TileGrid& grid;
  std::string output_dir;
  const detail::TileGeoref& georef;
  unsigned workers = 1;
};

// Builds levels 1, 2, ... until one file covers every tile (or the depth allows no
// coarser level); files go to OUTDIR/overviews/L<level>/. Collective over `comm`.
std::vector<OverviewEntry> build_overviews(
    const std::vector<TileEntry>& tiles, const OverviewContext& context, Communicator& comm,
    const std::function<void(const std::string&, std::uint64_t, std::uint64_t)>& progress);

}  // namespace vola::tile
