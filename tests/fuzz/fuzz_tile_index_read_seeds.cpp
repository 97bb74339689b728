// Seeds for fuzz_tile_index_read: tile indexes written by write_tile_index (the writer
// vola tile uses), one per LAS file of the shared data folder (beside golden/) over the
// tiles its header's bounding box covers, plus synthetic ones: no CRS, negative tiles,
// overviews, generation folders, an empty set. Linked into fuzz_tile_index_read_replay
// in place of fuzz_seeds.cpp.
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>
#include <string>

#include "fuzz_seeds.hpp"
#include "vola/tile/tile_index.hpp"

namespace vola_fuzz {
namespace {

namespace tile = vola::tile;
using Bytes = std::vector<std::uint8_t>;

Bytes bytes_of(const tile::TileIndexFile& index) {
  const auto path = std::filesystem::temp_directory_path() /
                    ("vola_fuzz_tile_index_seed_" + std::to_string(::getpid()) + ".geojson");
  tile::write_tile_index(index, path.string());
  std::ifstream in(path, std::ios::binary);
  Bytes b{std::istreambuf_iterator<char>(in), {}};
  std::filesystem::remove(path);
  std::filesystem::remove(std::filesystem::path(path).replace_extension(".gpkg"));  // the index's native-CRS twin
  return b;
}

// Tiles of `size` covering [lo, hi] (at most 4 per axis), files in `folder`.
tile::TileIndexFile covering(const vola::Point& lo, const vola::Point& hi, double size, int depth,
                             const std::string& folder) {
  tile::TileIndexFile index;
  index.grid.origin = {std::floor(lo[0] / size) * size, std::floor(lo[1] / size) * size, std::floor(lo[2] / size) * size};
  index.grid.tile_size = size;
  index.grid.depth = depth;
  std::array<int, 3> n{};
  for (int a = 0; a < 3; ++a) n[a] = std::clamp(static_cast<int>(std::ceil((hi[a] - index.grid.origin[a]) / size)), 1, 4);
  for (int i = 0; i < n[0]; ++i)
    for (int j = 0; j < n[1]; ++j)
      for (int k = 0; k < n[2]; ++k) {
        tile::TileEntry e;
        e.tile = {i, j, k};
        e.file = folder + tile::tile_file_name(e.tile);
        e.points = static_cast<std::uint64_t>(100 * (i + 1) + j);
        e.voxels = e.points / 2;
        e.bytes = 80 + 8 * e.voxels;
        e.bbox = index.grid.tile_box(e.tile);
        index.points_in += e.points;
        index.tiles.push_back(e);
      }
  return index;
}

}  // namespace

std::vector<Seed> synthetic_seeds() {
  std::vector<Seed> seeds;
  tile::TileIndexFile plain = covering({0, 0, 0}, {250, 120, 30}, 100, 4, "");
  seeds.push_back({"index_plain", bytes_of(plain)});
  tile::TileIndexFile crs = covering({500000, 5000000, 80}, {500600, 5000300, 140}, 200, 6, ".generation-2/");
  crs.epsg = 32633;
  crs.crs_wkt = "PROJCRS[\"WGS 84 / UTM zone 33N\",BASEGEOGCRS[\"WGS 84\"],ID[\"EPSG\",32633]]";
  crs.overviews.push_back({1, {0, 0, 0}, ".generation-2/overviews/L1/tile_0_0_0.vol", 42});
  crs.overviews.push_back({2, {0, 0, 0}, ".generation-2/overviews/L2/tile_0_0_0.vol", 7});
  seeds.push_back({"index_crs_overviews", bytes_of(crs)});
  tile::TileIndexFile negative = covering({-900, -300, -50}, {-100, 100, 10}, 256, 10, "tiles/");
  seeds.push_back({"index_negative", bytes_of(negative)});
  tile::TileIndexFile empty = plain;
  empty.tiles.clear();
  seeds.push_back({"index_empty", bytes_of(empty)});
  return seeds;
}

// One index per LAS file of data/las: the tiles its header's bounding box covers.
std::vector<Seed> golden_seeds(const std::filesystem::path& golden) {
  std::vector<Seed> seeds;
  const auto folder = golden.parent_path() / "data" / "las";
  if (!std::filesystem::is_directory(folder)) return seeds;
  for (const auto& entry : std::filesystem::directory_iterator(folder)) {
    if (!entry.is_regular_file() || entry.path().extension() != ".las") continue;
    std::ifstream in(entry.path(), std::ios::binary);
    char header[227] = {};
    if (!in.read(header, sizeof header)) continue;
    double b[6];  // max x, min x, max y, min y, max z, min z (LAS 1.0-1.4, byte 179)
    std::memcpy(b, header + 179, sizeof b);
    if (!std::all_of(b, b + 6, [](double v) { return std::isfinite(v); })) continue;
    const double extent = std::max({b[0] - b[1], b[2] - b[3], 1.0});
    tile::TileIndexFile index = covering({b[1], b[3], b[5]}, {b[0], b[2], b[4]}, std::ceil(extent / 3), 5, "");
    seeds.push_back({"index_" + entry.path().stem().string(), bytes_of(index)});
  }
  std::sort(seeds.begin(), seeds.end(), [](const Seed& a, const Seed& b) { return a.name < b.name; });
  return seeds;
}

}  // namespace vola_fuzz
