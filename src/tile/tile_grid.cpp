#include "vola/tile/tile_grid.hpp"

#include <cmath>

#include "vola/error.hpp"

namespace vola::tile {

Locator::Locator(const TileGrid& grid) noexcept
    : origin_(grid.origin),
      voxel_(grid.voxel_size()),
      limit_(std::ldexp(1.0, 31 + 2 * grid.depth)),
      shift_(2 * grid.depth),
      mask_((std::int64_t{1} << (2 * grid.depth)) - 1) {}

bool TileGrid::locate(const Point& p, TileIndex& tile, Key& key) const noexcept {
  return Locator(*this).locate(p, tile, key);
}

Point TileGrid::tile_origin(const TileIndex& t) const noexcept {
  return {origin[0] + t.i * tile_size, origin[1] + t.j * tile_size, origin[2] + t.k * tile_size};
}

Box TileGrid::tile_box(const TileIndex& t) const noexcept {
  const Point o = tile_origin(t);
  return {o, {o[0] + tile_size, o[1] + tile_size, o[2] + tile_size}};
}

Frame TileGrid::tile_frame(const TileIndex& t) const noexcept {
  Frame f;
  f.quantization = Quantization::grid;
  f.origin = tile_origin(t);
  f.voxel_size = voxel_size();
  return f;
}

void TileGrid::check() const {
  if (!(tile_size > 0.0) || !std::isfinite(tile_size))
    throw OptionError("tile_size", "must be a positive number (got " + std::to_string(tile_size) + ")");
  if (depth < kMinDepth || depth > kMaxDepth)
    throw OptionError("depth", "must be 1..10 (got " + std::to_string(depth) + ")");
  for (const double o : origin)
    if (!std::isfinite(o)) throw OptionError("origin", "must be finite");
}

std::string tile_file_name(const TileIndex& t) {
  return "tile_" + std::to_string(t.i) + "_" + std::to_string(t.j) + "_" + std::to_string(t.k) + ".vol";
}

}  // namespace vola::tile
