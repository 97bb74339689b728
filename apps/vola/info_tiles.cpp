// vola info on a tile set (the index.geojson vola tile writes, its folder or the
// index.gpkg beside it): the grid, the CRS, the tiles' counts and bounds, the attribute
// columns and the overview pyramid, from the index (no tile is opened; each file's size
// is checked against the index).
#include "info_tiles.hpp"

#include <cstdio>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "text_output.hpp"
#include "vola/error.hpp"
#include "vola/geo/crs.hpp"
#include "vola/io/input.hpp"
#include "vola/tile/tile_index.hpp"

namespace vola::cli {

namespace {

using nlohmann::ordered_json;

struct TileTotals {
  std::uint64_t voxels = 0, bytes = 0, points = 0;
  Box bbox;  // of every tile's points
  bool any = false;
};

TileTotals totals_of(const tile::TileIndexFile& index) {
  TileTotals t;
  for (const tile::TileEntry& e : index.tiles) {
    t.voxels += e.voxels;
    t.bytes += e.bytes;
    t.points += e.points;
    for (int a = 0; a < 3; ++a) {
      t.bbox.min[a] = t.any ? std::min(t.bbox.min[a], e.bbox.min[a]) : e.bbox.min[a];
      t.bbox.max[a] = t.any ? std::max(t.bbox.max[a], e.bbox.max[a]) : e.bbox.max[a];
    }
    t.any = true;
  }
  return t;
}

std::optional<geo::CrsDescription> describe(const tile::TileIndexFile& index) {
  if (index.crs_wkt.empty() && !index.epsg) return std::nullopt;
  try {
    return geo::describe_crs(!index.crs_wkt.empty() ? index.crs_wkt : "EPSG:" + std::to_string(*index.epsg));
  } catch (const Error&) {
    return std::nullopt;
  }
}

// The index's files that are not there, or not of the size it lists (a tile deleted or
// rewritten since): info reads the index alone, so the set looked whole without this.
struct FileCheck {
  std::vector<std::string> missing, resized;
};

FileCheck check_files(const tile::TileIndexFile& index, const std::string& index_path) {
  namespace fs = std::filesystem;
  const fs::path folder = fs::path(index_path).parent_path();
  FileCheck check;
  std::error_code ec;
  for (const tile::TileEntry& e : index.tiles) {
    const std::uintmax_t size = fs::file_size(folder / e.file, ec);
    if (ec)
      check.missing.push_back(e.file);
    else if (e.bytes != 0 && size != e.bytes)
      check.resized.push_back(e.file);
  }
  for (const tile::OverviewEntry& o : index.overviews)
    if (!fs::is_regular_file(folder / o.file, ec)) check.missing.push_back(o.file);
  return check;
}

}  // namespace

std::optional<std::string> tile_index_of(const std::string& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (fs::is_directory(path, ec)) {
    const fs::path index = fs::path(path) / tile::kIndexFileName;
    if (!fs::is_regular_file(index, ec))
      throw InvalidArgument(path + " is a folder with no " + tile::kIndexFileName +
                            ": vola info reads a file, or a tile set's folder (vola tile -o FOLDER)");
    return index.string();
  }
  const std::string extension = io::lower_extension(path);
  if (extension == ".geojson") return path;
  if (extension == ".gpkg") {  // vola tile writes the GeoPackage beside the index it reads
    const fs::path index = fs::path(path).replace_extension(".geojson");
    if (fs::is_regular_file(index, ec)) return index.string();
    throw InvalidArgument(path + ": vola reads a tile set from its GeoJSON index, and there is no " +
                          index.filename().string() + " beside this GeoPackage");
  }
  return std::nullopt;
}

void print_tile_index_info(const std::string& path, bool json) {
  const tile::TileIndexFile index = tile::read_tile_index(path);
  const TileTotals t = totals_of(index);
  const FileCheck files = check_files(index, path);
  const std::size_t listed = index.tiles.size() + index.overviews.size();
  if (!files.missing.empty())
    std::fprintf(stderr,
                 "vola: warning: %s lists %zu of its %zu files that are not there (first: %s); run vola tile again\n",
                 path.c_str(), files.missing.size(), listed, files.missing.front().c_str());
  if (!files.resized.empty())
    std::fprintf(stderr,
                 "vola: warning: %s: %zu tiles are not of the size the index lists (first: %s): changed since vola "
                 "tile wrote them\n",
                 path.c_str(), files.resized.size(), files.resized.front().c_str());
  const auto crs = describe(index);
  std::map<int, std::size_t> overviews;  // level -> files
  for (const tile::OverviewEntry& o : index.overviews) ++overviews[o.level];
  const tile::TileGrid& g = index.grid;
  if (json) {
    ordered_json levels = ordered_json::array();
    for (const auto& [level, count] : overviews) levels.push_back({{"level", level}, {"files", count}});
    ordered_json doc = {
        {"file", path},
        {"kind", "tile index"},
        {"crs", crs ? ordered_json({{"name", crs->name},
                                    {"epsg", crs->epsg ? ordered_json(*crs->epsg) : ordered_json(nullptr)},
                                    {"unit", crs->horizontal_unit},
                                    {"vertical", crs->vertical_name.empty() ? ordered_json(nullptr)
                                                                            : ordered_json(crs->vertical_name)}})
                    : ordered_json(nullptr)},
        {"grid",
         {{"origin", {g.origin[0], g.origin[1], g.origin[2]}},
          {"tile_size", g.tile_size},
          {"depth", g.depth},
          {"voxel_size", g.voxel_size()}}},
        {"tiles", index.tiles.size()},
        {"voxels", t.voxels},
        {"bytes", t.bytes},
        {"points", t.points},
        {"points_outside", index.points_outside},
        {"bounds", t.any ? ordered_json({{"min", {t.bbox.min[0], t.bbox.min[1], t.bbox.min[2]}},
                                         {"max", {t.bbox.max[0], t.bbox.max[1], t.bbox.max[2]}}})
                         : ordered_json(nullptr)},
        {"attributes", index.attributes},
        {"overviews", levels},
        {"missing_files", files.missing},
        {"resized_files", files.resized}};
    std::printf("%s\n", doc.dump(2, ' ', false, nlohmann::json::error_handler_t::replace).c_str());
    return;
  }
  std::printf("tile index:  %s\n", path.c_str());
  std::printf("crs:         %s\n", crs ? geo::crs_summary(*crs).c_str() : "none stated");
  std::printf("grid:        tiles of %s at depth %d (%u^3 voxels of %s), origin (%s, %s, %s)\n",
              shortest_text(g.tile_size).c_str(), g.depth, side_of(g.depth), shortest_text(g.voxel_size()).c_str(),
              shortest_text(g.origin[0]).c_str(), shortest_text(g.origin[1]).c_str(),
              shortest_text(g.origin[2]).c_str());
  std::printf("tiles:       %zu, %llu voxels, %llu bytes\n", index.tiles.size(),
              static_cast<unsigned long long>(t.voxels), static_cast<unsigned long long>(t.bytes));
  std::printf("points:      %llu in the tiles", static_cast<unsigned long long>(t.points));
  if (index.points_outside)
    std::printf(" (%llu not finite or beyond the tile range, dropped)",
                static_cast<unsigned long long>(index.points_outside));
  std::printf("\n");
  if (t.any)
    std::printf("bounds:      min (%s, %s, %s)\n             max (%s, %s, %s)\n", shortest_text(t.bbox.min[0]).c_str(),
                shortest_text(t.bbox.min[1]).c_str(), shortest_text(t.bbox.min[2]).c_str(),
                shortest_text(t.bbox.max[0]).c_str(), shortest_text(t.bbox.max[1]).c_str(),
                shortest_text(t.bbox.max[2]).c_str());
  std::string columns;
  for (const std::string& a : index.attributes) columns += (columns.empty() ? "" : ", ") + a;
  std::printf("attributes:  %s\n", columns.empty() ? "none (occupancy only)" : columns.c_str());
  if (overviews.empty()) std::printf("overviews:   none\n");
  for (const auto& [level, count] : overviews)
    std::printf("overviews:   level %d (voxels %d times the tiles'), %zu files\n", level, 1 << (2 * level), count);
  if (files.missing.empty() && files.resized.empty())
    std::printf("files:       all %zu present, of the sizes listed\n", listed);
  else
    std::printf("files:       %zu of %zu missing, %zu of another size\n", files.missing.size(), listed,
                files.resized.size());
}

}  // namespace vola::cli
