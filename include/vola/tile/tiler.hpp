// `vola tile`: point clouds of any size into a grid of georeferenced .vol tiles, a
// GeoJSON tile index and an overview pyramid, in bounded memory, on all cores and,
// under mpirun, on many processes.
//
// 1. Bucket: each worker takes chunks of the input, places every point in its tile
//    (TileGrid::locate) and appends the voxel key to that tile's buffer; when a
//    worker's buffers reach its share of the memory budget they are sorted, made
//    unique and appended to the worker's spill file as one run per tile.
// 2. Exchange (MPI only): tiles are dealt round-robin to ranks in index order; every
//    rank sends its merged keys of each tile it does not own to the tile's owner.
// 3. Build: each tile's runs are merged into sorted unique keys, built into a tree and
//    written. The keys of a tile do not depend on who read which chunk, so the files
//    are byte-identical for any thread count and any number of ranks.
// 4. Overviews: level L has tiles of 4^L x 4^L x 4^L base tiles at the same depth
//    (voxels 4^L times larger), each built from the level below's coarser cells.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "vola/tile/communicator.hpp"
#include "vola/tile/point_source.hpp"
#include "vola/tile/tile_grid.hpp"

namespace vola::tile {

struct TileOptions {
  TileGrid grid;
  std::string output_dir;
  // Spill files go to spill_dir/rank-<r> (default: output_dir/.spill); removed at the end.
  std::string spill_dir;
  // Per process: key buffers, sort scratch and merge buffers stay within it; a tile's
  // own voxel keys (8 bytes each) must fit it when the tile is built.
  std::uint64_t memory_budget = std::uint64_t{2} << 30;
  unsigned threads = 0;  // 0 = vola::thread_count() (all cores unless set)
  bool overviews = true;
  // Keep the inputs' attribute columns (those every input carries, as `vola convert`
  // keeps them, with the same reductions): points are reduced into each tile's voxels in
  // input order, so the values do not depend on threads, memory or ranks either.
  bool attributes = true;
  // More tiles than this (0: no limit) is refused once the points are bucketed, before
  // any tile is written: a tile size far below the point spacing made one tile per point
  // (a 3.7 MB survey became 440,000 files and 2 GB).
  std::uint64_t max_tiles = 100'000;
  // The CRS written into every tile (header code and WKT); the caller resolves it.
  std::optional<std::uint32_t> epsg;
  std::string crs_wkt;
  // (stage, done, total) on rank 0, from the calling thread.
  std::function<void(const std::string&, std::uint64_t, std::uint64_t)> progress;
};

struct TileSummary {
  std::uint64_t points_in = 0;        // over all ranks
  std::uint64_t points_outside = 0;   // not finite, or beyond the 32-bit tile index range
  std::uint64_t tiles = 0;
  std::uint64_t voxels = 0;           // over all tiles
  std::uint64_t tile_bytes = 0;       // .vol bytes over all tiles
  std::uint64_t overview_files = 0;
  std::uint64_t spill_runs = 0;       // this rank's
  std::uint64_t spill_bytes = 0;      // this rank's
  std::string index_path;
  std::vector<std::string> attributes;  // the columns every tile carries
  std::vector<std::string> warnings;    // columns left out, and why
  // Wall time of each step on this rank.
  double seconds_bucket = 0, seconds_exchange = 0, seconds_build = 0, seconds_overviews = 0;
};

// Points per work unit (a LAS source's chunk) that suit the options: 2^20 for occupancy;
// with attributes 2^18, or fewer when the budget is small, so that the chunks being read
// (about 160 bytes a point in flight with their decoded fields and values) take at most a
// quarter of it. Any chunking gives the same tiles.
std::size_t chunk_points_for(const TileOptions& options);

// Throws vola::Error on bad input or when the output cannot be written. Every rank of
// `comm` must call it with the same sources and options.
TileSummary make_tiles(const std::vector<const PointSource*>& sources, const TileOptions& options,
                       Communicator& comm);

}  // namespace vola::tile
