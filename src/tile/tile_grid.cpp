#include "vola/tile/tile_grid.hpp"

#include <cmath>

#include "vola/error.hpp"

namespace vola::tile {

bool TileGrid::locate(const Point& p, TileIndex& tile, Key& key) const noexcept {
  const double inverse = 1.0 / voxel_size();
  const int shift = 2 * depth;
  std::int32_t t[3];
  std::uint32_t local[3];
  for (int a = 0; a < 3; ++a) {
    const double g = std::floor((p[a] - origin[a]) * inverse);
    // 2^31 tiles of 4^D voxels each way: beyond that the index does not fit.
    if (!(std::abs(g) < std::ldexp(1.0, 31 + shift))) return false;
    const auto global = static_cast<std::int64_t>(g);
    t[a] = static_cast<std::int32_t>(global >> shift);  // arithmetic shift: floor division
    local[a] = static_cast<std::uint32_t>(global & ((std::int64_t{1} << shift) - 1));
  }
  tile = TileIndex{t[0], t[1], t[2]};
  key = encode(local[0], local[1], local[2]);
  return true;
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
    throw InvalidArgument("--tile-size must be a positive number (got " + std::to_string(tile_size) + ")");
  if (depth < kMinDepth || depth > kMaxDepth)
    throw InvalidArgument("--depth must be 1..10 (got " + std::to_string(depth) + ")");
  for (const double o : origin)
    if (!std::isfinite(o)) throw InvalidArgument("--origin must be finite");
}

std::string tile_file_name(const TileIndex& t) {
  return "tile_" + std::to_string(t.i) + "_" + std::to_string(t.j) + "_" + std::to_string(t.k) + ".vol";
}

}  // namespace vola::tile
