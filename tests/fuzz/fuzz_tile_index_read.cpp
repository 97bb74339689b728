// Fuzz entry point of the tile index reader (tile::read_tile_index, what vola get,
// render, plan, TileSet and the Python module read first): the input is an index.geojson,
// written to a scratch file of this process. Only vola::Error may escape (nlohmann's own
// exceptions, a number too large for its type, must have become FormatErrors); what reads
// must hold what TileSet relies on: a grid that passes check(), tiles sorted and unique,
// every file a path inside the index's folder, finite tile boxes.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <span>
#include <string>

#include "fuzz_seeds.hpp"
#include "scratch_file.hpp"
#include "vola/error.hpp"
#include "vola/tile/tile_index.hpp"

namespace {

using vola_fuzz::check;

void check_file(const std::string& file) {
  check(!file.empty() && file.front() != '/' && file.find("..") == std::string::npos);
}

void check_index(const vola::tile::TileIndexFile& index) {
  index.grid.check();  // throws InvalidArgument, a vola::Error, which the reader must have caught
  for (std::size_t i = 0; i < index.tiles.size(); ++i) {
    const auto& t = index.tiles[i];
    check_file(t.file);
    if (i > 0) check(index.tiles[i - 1].tile < t.tile);
    const vola::Box box = index.grid.tile_box(t.tile);
    for (int a = 0; a < 3; ++a) check(std::isfinite(box.min[a]) && std::isfinite(box.max[a]) && box.min[a] <= box.max[a]);
  }
  for (const auto& o : index.overviews) check_file(o.file);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path = vola_fuzz::scratch_file("tile_index", "geojson", std::span(data, size));
  try {
    check_index(vola::tile::read_tile_index(path));
    ++vola_fuzz::stats().parsed;
  } catch (const vola::InvalidArgument&) {
    std::abort();  // a grid the reader let through
  } catch (const vola::Error&) {
    ++vola_fuzz::stats().refused;
  }
  return 0;
}
