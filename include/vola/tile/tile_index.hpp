// The tile index `vola tile` writes beside its tiles: a GeoJSON FeatureCollection with
// one Polygon feature per tile (its footprint in the CRS's units; properties: file,
// tile index, points, voxels, bytes, the points' bbox) and a "vola" member holding the
// grid (origin, tile size, depth, voxel size), the CRS and the overview pyramid.
// Desktop GIS opens it as a footprint layer; vola get / render / plan and the Python
// module open it as one scene whose tiles are mapped only when a query needs them.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "vola/frame.hpp"
#include "vola/tile/tile_grid.hpp"

namespace vola::tile {

struct TileEntry {
  TileIndex tile;
  std::string file;  // relative to the index's folder
  std::uint64_t points = 0;
  std::uint64_t voxels = 0;
  std::uint64_t bytes = 0;
  Box bbox;  // of the tile's points
};

struct OverviewEntry {
  int level = 1;  // voxels 4^level times the tiles' voxels
  TileIndex tile; // on the level's grid of 4^level times the tile size
  std::string file;
  std::uint64_t voxels = 0;
};

struct TileIndexFile {
  TileGrid grid;
  std::optional<std::uint32_t> epsg;
  std::string crs_wkt;
  std::uint64_t points_in = 0;
  std::uint64_t points_outside = 0;
  std::vector<std::string> attributes;   // the attribute columns every tile and overview carries
  std::vector<TileEntry> tiles;          // sorted by tile index
  std::vector<OverviewEntry> overviews;  // by level, then tile index
};

inline constexpr const char* kIndexFileName = "index.geojson";

// Deterministic bytes for the same contents.
void write_tile_index(const TileIndexFile& index, const std::string& path);
// Throws FormatError naming the file and what is wrong or missing.
TileIndexFile read_tile_index(const std::string& path);
// Whether `path` looks like a tile index (a .geojson or .json file) rather than a .vol.
bool is_tile_index_path(const std::string& path);

}  // namespace vola::tile
