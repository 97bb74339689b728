// The tile index `vola tile` writes beside its tiles, through OGR (GDAL's GeoJSON and
// GPKG drivers, vola/io/footprints.hpp):
//  - index.geojson, an RFC 7946 FeatureCollection: one Polygon per tile, its footprint in
//    WGS84 longitude/latitude (null when the CRS is unknown or cannot reach WGS84), with
//    properties file, tile [i, j, k], points, voxels, bytes and the points' bbox in the
//    CRS's units; and a "vola" member holding the grid (origin, tile size, depth, voxel
//    size), the CRS (EPSG code, WKT) and the overview pyramid. vola get / render / plan
//    and the Python module open it as one scene whose tiles are mapped only when a query
//    needs them.
//  - index.gpkg, a GeoPackage of the same footprints in the survey's own CRS (one column
//    per value), for desktop GIS.
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

// Writes index.gpkg beside `path` (its extension replaced), then `path`, each whole
// through a temporary renamed into place. Deterministic bytes for the same contents.
void write_tile_index(const TileIndexFile& index, const std::string& path);
// Throws FormatError naming the file and what is wrong or missing.
TileIndexFile read_tile_index(const std::string& path);
// Whether `path` looks like a tile index (a .geojson or .json file) rather than a .vol.
bool is_tile_index_path(const std::string& path);

}  // namespace vola::tile
