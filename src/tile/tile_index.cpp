#include "vola/tile/tile_index.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <sstream>

#include "vola/error.hpp"
#include "vola/geo/crs.hpp"
#include "vola/io/footprints.hpp"
#include "vola/output_file.hpp"

namespace vola::tile {

namespace {

using nlohmann::json;
using nlohmann::ordered_json;

using io::FootprintField;
using FieldType = io::FootprintField::Type;

std::vector<std::int64_t> tile_list(const TileIndex& t) { return {t.i, t.j, t.k}; }
std::vector<double> box_list(const Box& b) { return {b.min[0], b.min[1], b.min[2], b.max[0], b.max[1], b.max[2]}; }
std::int64_t count(std::uint64_t n) { return static_cast<std::int64_t>(n); }

// The index's CRS as WKT: its own, else its code's, else none.
std::string index_crs_wkt(const TileIndexFile& index) {
  if (!index.crs_wkt.empty() || !index.epsg) return index.crs_wkt;
  return geo::crs_wkt(*index.epsg);
}

// What vola reads back: per tile, `file`, `tile` [i, j, k], the counts and the points'
// `bbox` [min x y z, max x y z].
io::FootprintLayer geojson_layer(const TileIndexFile& index, const std::string& wkt) {
  io::FootprintLayer layer{"tiles", wkt,
                           {{"file", FieldType::text},
                            {"tile", FieldType::integer_list},
                            {"points", FieldType::integer},
                            {"voxels", FieldType::integer},
                            {"bytes", FieldType::integer},
                            {"bbox", FieldType::real_list}},
                           {}};
  for (const TileEntry& t : index.tiles) {
    const Box box = index.grid.tile_box(t.tile);
    layer.features.push_back({box.min[0], box.min[1], box.max[0], box.max[1],
                              {t.file, tile_list(t.tile), count(t.points), count(t.voxels), count(t.bytes),
                               box_list(t.bbox)}});
  }
  return layer;
}

// What a desktop GIS shows best: one scalar column per value.
io::FootprintLayer geopackage_layer(const TileIndexFile& index, const std::string& wkt) {
  io::FootprintLayer layer{"tiles", wkt, {{"file", FieldType::text}}, {}};
  for (const char* name : {"tile_i", "tile_j", "tile_k", "points", "voxels", "bytes"})
    layer.fields.push_back({name, FieldType::integer});
  for (const char* name : {"min_x", "min_y", "min_z", "max_x", "max_y", "max_z"})
    layer.fields.push_back({name, FieldType::real});
  for (const TileEntry& t : index.tiles) {
    const Box box = index.grid.tile_box(t.tile);
    io::Footprint f{box.min[0], box.min[1], box.max[0], box.max[1], {t.file}};
    for (const std::int64_t v : {std::int64_t{t.tile.i}, std::int64_t{t.tile.j}, std::int64_t{t.tile.k}, count(t.points),
                                 count(t.voxels), count(t.bytes)})
      f.values.emplace_back(v);
    for (const double v : box_list(t.bbox)) f.values.emplace_back(v);
    layer.features.push_back(std::move(f));
  }
  return layer;
}

ordered_json vola_member(const TileIndexFile& index) {
  ordered_json vola;
  vola["format"] = "vola-tile-index";
  vola["version"] = 1;
  vola["origin"] = ordered_json::array({index.grid.origin[0], index.grid.origin[1], index.grid.origin[2]});
  vola["tile_size"] = index.grid.tile_size;
  vola["depth"] = index.grid.depth;
  vola["voxel_size"] = index.grid.voxel_size();
  if (index.epsg) vola["epsg"] = *index.epsg;
  else vola["epsg"] = nullptr;
  vola["crs_wkt"] = index.crs_wkt;
  vola["points_in"] = index.points_in;
  vola["points_outside"] = index.points_outside;
  std::uint64_t voxels = 0;
  for (const TileEntry& t : index.tiles) voxels += t.voxels;
  vola["tiles"] = index.tiles.size();
  vola["voxels"] = voxels;
  vola["attributes"] = index.attributes;
  ordered_json overviews = ordered_json::array();
  for (const OverviewEntry& o : index.overviews)
    overviews.push_back({{"level", o.level},
                         {"tile", ordered_json::array({o.tile.i, o.tile.j, o.tile.k})},
                         {"file", o.file},
                         {"voxels", o.voxels}});
  vola["overviews"] = std::move(overviews);
  return vola;
}

void write_whole(const std::vector<std::uint8_t>& bytes, const std::string& path) {
  OutputFile out(path);
  out.write(bytes.data(), bytes.size());
  out.commit();
}

[[noreturn]] void bad(const std::string& path, const std::string& what) {
  throw FormatError(path, 0, "not a vola tile index: " + what);
}

// A JSON number as an integer of type Int, refused unless it is one and fits: nlohmann's
// get<Int>() converts any number, and a double beyond Int's range is undefined behaviour.
template <class Int>
Int whole(const json& j, const std::string& path, const std::string& what) {
  constexpr auto lo = static_cast<long double>(std::numeric_limits<Int>::min());
  constexpr auto hi = static_cast<long double>(std::numeric_limits<Int>::max());
  long double v = 0;
  if (j.is_number_unsigned()) v = static_cast<long double>(j.get<std::uint64_t>());
  else if (j.is_number_integer()) v = static_cast<long double>(j.get<std::int64_t>());
  else if (j.is_number_float() && std::isfinite(j.get<double>()) && j.get<double>() == std::floor(j.get<double>()))
    v = j.get<double>();
  else bad(path, what + " must be an integer");
  if (v < lo || v > hi) bad(path, what + " is out of range");
  return static_cast<Int>(v);
}

// An optional count member: 0 when absent.
std::uint64_t count_of(const json& object, const char* key, const std::string& path) {
  return object.contains(key) ? whole<std::uint64_t>(object[key], path, std::string("\"") + key + "\"") : 0;
}

TileIndex tile_of(const json& j, const std::string& path, const std::string& where) {
  if (!j.is_array() || j.size() != 3) bad(path, where + ": \"tile\" must be [i, j, k]");
  TileIndex t;
  t.i = whole<std::int32_t>(j[0], path, where + ": \"tile\"");
  t.j = whole<std::int32_t>(j[1], path, where + ": \"tile\"");
  t.k = whole<std::int32_t>(j[2], path, where + ": \"tile\"");
  return t;
}

std::string relative_file(const json& j, const std::string& path, const std::string& where) {
  if (!j.is_string()) bad(path, where + ": \"file\" must be a string");
  const std::string f = j.get<std::string>();
  // A file name, never a path out of the index's folder.
  if (f.empty() || f.front() == '/' || f.find("..") != std::string::npos)
    bad(path, where + ": \"file\" must be a path inside the index's folder (got '" + f + "')");
  return f;
}

}  // namespace

void write_tile_index(const TileIndexFile& index, const std::string& path) {
  const std::string wkt = index_crs_wkt(index);
  // The GeoPackage first: the GeoJSON index, renamed into place last, is the switch.
  write_whole(io::footprints_geopackage(geopackage_layer(index, wkt)),
              std::filesystem::path(path).replace_extension(".gpkg").string());
  const ordered_json members = {{"vola", vola_member(index)}};
  write_whole(io::footprints_geojson(geojson_layer(index, wkt), members.dump()), path);
}

TileIndexFile read_tile_index(const std::string& path) {
  std::error_code error;
  if (std::filesystem::is_directory(path, error))  // the tile folder: its index is the file inside
    throw IoError(path + ": is a folder; open the tile set's index, " +
                  (std::filesystem::path(path) / "index.geojson").string());
  std::ifstream in(path, std::ios::binary);
  if (!in) throw IoError(path + ": cannot open");
  json root;
  try {
    root = json::parse(in);
  } catch (const json::parse_error& e) {
    throw FormatError(path, e.byte, std::string("not valid JSON: ") + e.what());
  } catch (const json::exception& e) {  // e.g. a number too large for a double
    throw FormatError(path, 0, std::string("not valid JSON: ") + e.what());
  }
  if (!root.is_object() || !root.contains("vola") || !root["vola"].is_object())
    bad(path, "no \"vola\" member (write one with vola tile)");
  const json& v = root["vola"];
  TileIndexFile index;
  try {  // a member of the wrong JSON type throws json::type_error: a FormatError below
    if (v.value("format", "") != "vola-tile-index") bad(path, "\"vola\".\"format\" is not \"vola-tile-index\"");
    if (!v.contains("version") || whole<int>(v["version"], path, "\"version\"") != 1)
      bad(path, "unsupported \"vola\".\"version\" (this vola reads version 1)");
    const auto origin = v.at("origin");
    if (!origin.is_array() || origin.size() != 3) bad(path, "\"origin\" must be [x, y, z]");
    for (int a = 0; a < 3; ++a) index.grid.origin[a] = origin[a].get<double>();
    index.grid.tile_size = v.at("tile_size").get<double>();
    index.grid.depth = whole<int>(v.at("depth"), path, "\"depth\"");
    if (!v.at("epsg").is_null()) index.epsg = whole<std::uint32_t>(v.at("epsg"), path, "\"epsg\"");
    index.crs_wkt = v.value("crs_wkt", "");
    index.points_in = count_of(v, "points_in", path);
    index.points_outside = count_of(v, "points_outside", path);
    if (v.contains("attributes")) {  // absent in indexes written before tiles had columns
      if (!v["attributes"].is_array()) bad(path, "\"attributes\" must be a list of column names");
      for (const json& name : v["attributes"]) {
        if (!name.is_string()) bad(path, "\"attributes\" must be a list of column names");
        index.attributes.push_back(name.get<std::string>());
      }
    }
    try {
      index.grid.check();
    } catch (const InvalidArgument& e) {
      bad(path, std::string("bad grid: ") + e.what());
    }
    if (!root.contains("features") || !root["features"].is_array()) bad(path, "no \"features\" array");
    std::size_t n = 0;
    for (const json& f : root["features"]) {
      const std::string where = "feature " + std::to_string(n++);
      if (!f.contains("properties") || !f["properties"].is_object()) bad(path, where + ": no properties");
      const json& p = f["properties"];
      TileEntry t;
      t.tile = tile_of(p.at("tile"), path, where);
      t.file = relative_file(p.at("file"), path, where);
      const Box box = index.grid.tile_box(t.tile);  // TileSet's ray and region arithmetic needs finite boxes
      for (int a = 0; a < 3; ++a)
        if (!std::isfinite(box.min[a]) || !std::isfinite(box.max[a]))
          bad(path, where + ": the tile lies beyond the range of coordinates (origin + index x tile size overflows)");
      t.points = count_of(p, "points", path);
      t.voxels = count_of(p, "voxels", path);
      t.bytes = count_of(p, "bytes", path);
      if (p.contains("bbox") && p["bbox"].is_array() && p["bbox"].size() == 6)
        for (int a = 0; a < 3; ++a) {
          t.bbox.min[a] = p["bbox"][a].get<double>();
          t.bbox.max[a] = p["bbox"][a + 3].get<double>();
        }
      index.tiles.push_back(std::move(t));
    }
    if (v.contains("overviews") && v["overviews"].is_array()) {
      n = 0;
      for (const json& o : v["overviews"]) {
        const std::string where = "overview " + std::to_string(n++);
        OverviewEntry e;
        e.level = whole<int>(o.at("level"), path, "an overview's \"level\"");
        e.tile = tile_of(o.at("tile"), path, where);
        e.file = relative_file(o.at("file"), path, where);
        e.voxels = count_of(o, "voxels", path);
        index.overviews.push_back(std::move(e));
      }
    }
  } catch (const json::exception& e) {
    bad(path, std::string("a member is missing or of the wrong type (") + e.what() + ")");
  }
  std::sort(index.tiles.begin(), index.tiles.end(), [](const TileEntry& a, const TileEntry& b) { return a.tile < b.tile; });
  for (std::size_t i = 1; i < index.tiles.size(); ++i)
    if (index.tiles[i].tile == index.tiles[i - 1].tile) bad(path, "tile " + index.tiles[i].file + " is listed twice");
  return index;
}

bool is_tile_index_path(const std::string& path) {
  const auto dot = path.rfind('.');
  if (dot == std::string::npos) return false;
  std::string ext = path.substr(dot);
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext == ".geojson" || ext == ".json";
}

}  // namespace vola::tile
