#include "vola/viewer/viewed_tile_set.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>

#include "crs_units.hpp"
#include "json_point.hpp"
#include "vola/error.hpp"

namespace vola::viewer {

namespace fs = std::filesystem;

namespace {

// The world box of tile `t` on the grid of level `level` (tile size times 4^level).
Box piece_box(const tile::TileGrid& grid, int level, const tile::TileIndex& t) {
  const double size = grid.tile_size * std::pow(4.0, level);
  const double index[3] = {static_cast<double>(t.i), static_cast<double>(t.j), static_cast<double>(t.k)};
  Box box;
  for (int a = 0; a < 3; ++a) {
    box.min[a] = grid.origin[a] + index[a] * size;
    box.max[a] = box.min[a] + size;
  }
  return box;
}

bool inside(const fs::path& folder, const fs::path& path) {
  const auto [f, p] = std::mismatch(folder.begin(), folder.end(), path.begin(), path.end());
  return f == folder.end() && p != path.end();
}

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr Box kEmpty{{kInf, kInf, kInf}, {-kInf, -kInf, -kInf}};

void grow(Box& box, const Box& by) {
  for (int a = 0; a < 3; ++a) {
    box.min[a] = std::min(box.min[a], by.min[a]);
    box.max[a] = std::max(box.max[a], by.max[a]);
  }
}

// The tile's index on the grid of overview level `level` (floor division by 4^level).
tile::TileIndex overview_tile(const tile::TileIndex& t, int level) {
  const int shift = 2 * level;
  return {t.i >> shift, t.j >> shift, t.k >> shift};
}

}  // namespace

ViewedTileSet::ViewedTileSet(const std::string& index_path, std::size_t max_open)
    : index_(tile::read_tile_index(index_path)), max_open_(max_open) {
  if (max_open == 0) throw InvalidArgument("a tile set needs room for at least one open piece");
  if (index_.tiles.empty()) throw FormatError(index_path, 0, "the tile index lists no tiles");
  const fs::path folder = fs::canonical(fs::absolute(index_path).parent_path());
  folder_ = folder.string();
  name_ = folder.filename().string();
  for (const auto& t : index_.tiles)
    pieces_.push_back({0, t.tile, t.file, t.voxels, piece_box(index_.grid, 0, t.tile), t.bbox});
  // An overview's points are those of the tiles it covers (the page measures distances
  // to them: the overview's own box is mostly empty).
  std::map<std::pair<int, tile::TileIndex>, Box> covered;
  int levels = 0;
  for (const auto& o : index_.overviews) {
    // 32-bit tile indexes: from level 16 up every tile has one overview (4^16 = 2^32).
    if (o.level < 1 || o.level > 16)
      throw FormatError(index_path, 0, o.file + ": overview level " + std::to_string(o.level) + " is outside 1..16");
    covered.emplace(std::pair{o.level, o.tile}, kEmpty);
    levels = std::max(levels, o.level);
  }
  for (const auto& t : index_.tiles)
    for (int level = 1; level <= levels; ++level) {
      const auto it = covered.find(std::pair{level, overview_tile(t.tile, level)});
      if (it != covered.end()) grow(it->second, t.bbox);
    }
  for (const auto& o : index_.overviews)
    pieces_.push_back({o.level, o.tile, o.file, o.voxels, piece_box(index_.grid, o.level, o.tile),
                       covered.at(std::pair{o.level, o.tile})});
}

ViewedTileSet::~ViewedTileSet() = default;

nlohmann::json ViewedTileSet::metadata() const {
  using nlohmann::json;
  const tile::TileGrid& grid = index_.grid;
  // The points' bounds (each tile's bbox), which the camera frames; the tiles' boxes
  // are whole grid cells and may be mostly empty.
  Box points = kEmpty;
  for (const auto& t : index_.tiles) grow(points, t.bbox);
  int levels = 0;
  json list = json::array();
  for (std::size_t id = 0; id < pieces_.size(); ++id) {
    const TilePiece& p = pieces_[id];
    levels = std::max(levels, p.level);
    list.push_back({{"id", id},
                    {"level", p.level},
                    {"tile", {p.tile.i, p.tile.j, p.tile.k}},
                    {"file", p.file},
                    {"voxels", p.voxels},
                    {"min", json_point(p.box.min)},
                    {"max", json_point(p.box.max)},
                    {"points_min", json_point(p.points.min)},
                    {"points_max", json_point(p.points.max)},
                    {"origin", json_point(p.box.min)},
                    {"voxel_size", grid.voxel_size() * std::pow(4.0, p.level)}});
  }
  Georef georef;
  if (index_.epsg) georef.epsg = *index_.epsg;
  georef.crs_wkt = index_.crs_wkt;
  const auto has = [&](const char* column) {
    return std::find(index_.attributes.begin(), index_.attributes.end(), column) != index_.attributes.end();
  };
  return {{"name", name_},
          {"origin", json_point(grid.origin)},
          {"tile_size", grid.tile_size},
          {"depth", grid.depth},
          {"voxel_size", grid.voxel_size()},
          {"epsg", index_.epsg ? json(*index_.epsg) : json(nullptr)},
          {"crs_wkt", index_.crs_wkt},
          {"units", crs_units(georef)},
          {"attributes", index_.attributes},
          {"has_classes", has("classification")},
          {"has_colours", has("red") && has("green") && has("blue")},
          {"points_min", json_point(points.min)},
          {"points_max", json_point(points.max)},
          {"tiles", index_.tiles.size()},
          {"overview_levels", levels},
          {"pieces", list}};
}

std::shared_ptr<const ViewedFile> ViewedTileSet::piece(std::size_t id) const {
  if (id >= pieces_.size())
    throw InvalidArgument(name_ + ": no piece " + std::to_string(id) + " (the set has " +
                          std::to_string(pieces_.size()) + ")");
  const std::lock_guard lock(mutex_);
  const auto it = std::find_if(open_.begin(), open_.end(), [id](const auto& e) { return e.first == id; });
  if (it != open_.end()) {
    open_.splice(open_.begin(), open_, it);
    return open_.front().second;
  }
  const fs::path folder(folder_);
  std::error_code error;
  const fs::path path = fs::canonical(folder / pieces_[id].file, error);
  if (error) throw IoError(name_ + "/" + pieces_[id].file + ": cannot open (" + error.message() + ")");
  if (!inside(folder, path))
    throw IoError(name_ + "/" + pieces_[id].file + ": lies outside the index's folder; not opened");
  std::shared_ptr<const ViewedFile> file;
  try {
    file = std::make_shared<const ViewedFile>(path.string());
  } catch (const Error&) {
    // The message names the full path, which is not the client's to know.
    throw FormatError(name_ + "/" + pieces_[id].file, 0, "not a .vol file vola can read");
  }
  if (open_.size() == max_open_) open_.pop_back();
  open_.emplace_front(id, file);
  return file;
}

std::size_t ViewedTileSet::pieces_open() const {
  const std::lock_guard lock(mutex_);
  return open_.size();
}

}  // namespace vola::viewer
