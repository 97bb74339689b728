// vola info on a tile set written by vola tile.
#pragma once

#include <optional>
#include <string>

namespace vola::cli {

// The tile index `path` names: the index.geojson of a folder (a folder without one is an
// InvalidArgument saying so), a .geojson file as it is, the .geojson beside a .gpkg;
// nothing for any other path.
std::optional<std::string> tile_index_of(const std::string& path);
// The grid, CRS, tiles (count, voxels, bytes, points, bounds), attribute columns and
// overview levels of a tile index, and its files missing or of another size than listed
// (warned of too); `json`: the same as one JSON object.
void print_tile_index_info(const std::string& index, bool json);

}  // namespace vola::cli
