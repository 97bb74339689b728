// A tile set opened through its index (vola tile's index.geojson): queries in world
// coordinates, each tile memory-mapped only when a query first needs it, so a query
// touches the tiles it needs and no others.
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>

#include "vola/raycast/camera.hpp"
#include "vola/raycast/ray.hpp"
#include "vola/raycast/render.hpp"
#include "vola/tile/tile_index.hpp"
#include "vola/tree.hpp"

namespace vola::tile {

struct TileLookup {
  bool in_tile = false;   // the point falls in a tile the set has
  TileIndex tile;
  Voxel voxel;            // inside that tile
  std::optional<std::uint64_t> rank;  // set when the voxel is occupied
};

struct TileHit {
  TileIndex tile;
  Voxel voxel;            // inside that tile
  double t = 0.0;         // world distance along the ray (unit direction) or ray parameter
  std::array<int, 3> normal{};
};

class TileSet {
 public:
  // Reads the index; opens no tile yet. Throws FormatError / IoError.
  explicit TileSet(const std::string& index_path);
  ~TileSet();

  const TileIndexFile& index() const noexcept { return index_; }
  const TileGrid& grid() const noexcept { return index_.grid; }
  // The tile's tree, mapped on first use (thread-safe); nullptr when the set has none.
  // locate(), cast() and mosaic() throw IoError naming the tile when its file was cut
  // since it was opened; whoever reads tree() itself calls check_mapped() (vola/file.hpp).
  const Tree* tree(const TileIndex& tile) const;
  std::size_t tiles_opened() const;
  // The world box of every tile together.
  Box bounds() const noexcept { return bounds_; }

  TileLookup locate(const Point& world) const;
  // The first occupied voxel along a world ray, tiles visited in the ray's order.
  std::optional<TileHit> cast(const raycast::Ray& world_ray) const;
  // The hit voxel's colour as raycast::VoxelColours gives it (its tile's red/green/blue
  // columns; light grey without them). `hit` is one cast() returned.
  std::array<double, 3> colour(const TileHit& hit) const;
  // One tree over the tiles that meet `world_box` (the grid of the lowest such tile),
  // for searches that need a single grid. Throws InvalidArgument when the region spans
  // more tiles per axis than depth 10 can hold.
  Tree mosaic(const Box& world_box) const;

 private:
  struct Opened;
  // Maps the tile on first use; throws FormatError when its file's grid is not its cell's.
  const Opened* open(const TileIndex& tile) const;
  void check_tile_place(const Tree& tree, const TileIndex& tile, const std::string& path) const;
  std::optional<TileHit> cast_in_tile(const TileIndex& tile, const raycast::Ray& world_ray) const;
  std::optional<TileHit> cast_listed(const raycast::Ray& world_ray, double t0, double t1) const;

  std::string folder_;
  TileIndexFile index_;
  std::map<TileIndex, std::size_t> entries_;  // tile -> position in index_.tiles
  Box bounds_;
  mutable std::mutex mutex_;
  mutable std::map<TileIndex, std::unique_ptr<Opened>> opened_;
};

// A shaded and a depth image of a tile set through a world-coordinate camera (depth
// in world units), shaded and coloured like raycast::render.
raycast::Rendering render(const TileSet& tiles, const raycast::PinholeCamera& world_camera, unsigned threads = 0);

// The default view of a tile set (world coordinates), placed as raycast::overview_camera
// places a tree's, over the points' bounding box of every tile (from the index: no tile
// is opened).
raycast::PinholeCamera overview_camera(const TileSet& tiles, const raycast::PinholeCamera& settings = {});

}  // namespace vola::tile
