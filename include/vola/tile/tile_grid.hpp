// A regular grid of tiles in world coordinates, the frame of `vola tile`.
//
// Tile (i, j, k) covers [origin + i*T, origin + (i+1)*T) per axis (T = tile size) and
// holds a depth-D tree of 4^D voxels per axis, voxel size T / 4^D. Points are placed by
// their global voxel index floor((p - origin) / voxel): the tile is that index divided
// by 4^D, the voxel inside the tile the remainder. So every tile of one grid shares one
// voxel lattice: tiles at the same depth line up voxel for voxel, whichever run made
// them, and no point can fall between two tiles or into two.
#pragma once

#include <array>
#include <cmath>
#include <compare>
#include <cstdint>
#include <string>

#include "vola/frame.hpp"
#include "vola/key.hpp"

namespace vola::tile {

struct TileIndex {
  std::int32_t i = 0, j = 0, k = 0;
  friend auto operator<=>(const TileIndex&, const TileIndex&) = default;
};

struct TileGrid {
  Point origin{0, 0, 0};
  double tile_size = 1000.0;
  int depth = 8;

  double voxel_size() const noexcept { return tile_size / static_cast<double>(side_of(depth)); }
  // False for a non-finite point or one whose tile index does not fit 32 bits.
  bool locate(const Point& p, TileIndex& tile, Key& key) const noexcept;
  Point tile_origin(const TileIndex& t) const noexcept;
  Box tile_box(const TileIndex& t) const noexcept;
  // The grid-mode frame of one tile's tree.
  Frame tile_frame(const TileIndex& t) const noexcept;
  // Throws InvalidArgument when the tile size, origin or depth cannot make a grid.
  void check() const;
};

// TileGrid::locate with its constants worked out once, for the per-point loop.
class Locator {
 public:
  explicit Locator(const TileGrid& grid) noexcept;
  bool locate(const Point& p, TileIndex& tile, Key& key) const noexcept {
    std::int32_t t[3];
    std::uint32_t local[3];
    for (int a = 0; a < 3; ++a) {
      // Divided, not multiplied by the inverse: vola::build's and Quantizer's arithmetic, so
      // that a point on a voxel's face lies in the voxel `vola convert` puts it in (with an
      // inverse that rounds, such points went to the other side, into the next tile too).
      const double g = std::floor((p[a] - origin_[a]) / voxel_);
      // 2^31 tiles of 4^D voxels each way: beyond that the index does not fit (NaN fails too).
      if (!(g > -limit_ && g < limit_)) return false;
      const auto global = static_cast<std::int64_t>(g);
      t[a] = static_cast<std::int32_t>(global >> shift_);  // arithmetic shift: floor division
      local[a] = static_cast<std::uint32_t>(global & mask_);
    }
    tile = TileIndex{t[0], t[1], t[2]};
    key = encode(local[0], local[1], local[2]);
    return true;
  }

 private:
  Point origin_;
  double voxel_, limit_;
  int shift_;
  std::int64_t mask_;
};

// "tile_3_-2_0.vol"
std::string tile_file_name(const TileIndex& t);

}  // namespace vola::tile
