#include "vola/filters/crop.hpp"

#include <cctype>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "vola/error.hpp"

namespace vola::filters {

bool PolygonSet::contains(double x, double y) const {
  for (const auto& polygon : polygons) {
    bool inside = false;
    for (const auto& ring : polygon) {
      const std::size_t n = ring.size();
      for (std::size_t i = 0, j = n - 1; i < n; j = i++) {
        const auto& a = ring[i];
        const auto& b = ring[j];
        if ((a[1] > y) != (b[1] > y) && x < (b[0] - a[0]) * (y - a[1]) / (b[1] - a[1]) + a[0]) inside = !inside;
      }
    }
    if (inside) return true;
  }
  return false;
}

namespace {

using Ring = PolygonSet::Ring;

// A ring of the set's last polygon.
void add_ring(PolygonSet& set, Ring ring, const std::string& name) {
  if (ring.size() < 3) throw InvalidArgument(name + ": a polygon ring needs 3 vertices or more");
  set.polygons.back().push_back(std::move(ring));
}

// GeoJSON coordinates of a Polygon ([[ [x, y], ... ], ...]): one polygon of the set.
void polygon_from_json(PolygonSet& set, const nlohmann::json& rings, const std::string& name) {
  if (!rings.is_array()) throw InvalidArgument(name + ": Polygon coordinates must be an array of rings");
  set.polygons.emplace_back();
  for (const auto& r : rings) {
    Ring ring;
    if (!r.is_array()) throw InvalidArgument(name + ": a ring must be an array of positions");
    for (const auto& p : r) {
      if (!p.is_array() || p.size() < 2 || !p[0].is_number() || !p[1].is_number())
        throw InvalidArgument(name + ": a position must be [x, y]");
      ring.push_back({p[0].get<double>(), p[1].get<double>()});
    }
    add_ring(set, std::move(ring), name);
  }
}

void geometry_from_json(PolygonSet& set, const nlohmann::json& j, const std::string& name) {
  const std::string type = j.value("type", "");
  if (type == "FeatureCollection") {
    for (const auto& f : j.at("features")) geometry_from_json(set, f, name);
  } else if (type == "Feature") {
    if (!j.contains("geometry") || j["geometry"].is_null()) throw InvalidArgument(name + ": a Feature has no geometry");
    geometry_from_json(set, j["geometry"], name);
  } else if (type == "Polygon") {
    polygon_from_json(set, j.at("coordinates"), name);
  } else if (type == "MultiPolygon") {
    for (const auto& p : j.at("coordinates")) polygon_from_json(set, p, name);
  } else {
    throw InvalidArgument(name + ": GeoJSON type '" + type + "' is not a polygon (Polygon, MultiPolygon, Feature, FeatureCollection)");
  }
}

// WKT: POLYGON ((x y, ...), (...)) or MULTIPOLYGON (((...)), ((...))); every innermost
// parenthesised list is a ring, of the polygon whose list opened at depth 1 (POLYGON) or
// 2 (MULTIPOLYGON).
void polygons_from_wkt(PolygonSet& set, const std::string& text, const std::string& name) {
  std::size_t i = 0;
  while (i < text.size() && std::isspace(static_cast<unsigned char>(text[i]))) ++i;
  std::string keyword;
  while (i < text.size() && std::isalpha(static_cast<unsigned char>(text[i])))
    keyword += static_cast<char>(std::toupper(static_cast<unsigned char>(text[i++])));
  if (keyword != "POLYGON" && keyword != "MULTIPOLYGON")
    throw InvalidArgument(name + ": expected WKT POLYGON or MULTIPOLYGON (or GeoJSON), found '" + keyword + "'");
  const int polygon_depth = keyword == "POLYGON" ? 1 : 2;
  int depth = 0;
  Ring ring;
  for (; i < text.size(); ++i) {
    const char c = text[i];
    if (c == '(') {
      if (++depth == polygon_depth) set.polygons.emplace_back();
      ring.clear();
    } else if (c == ')') {
      if (!ring.empty()) {
        if (depth <= polygon_depth - 1 || set.polygons.empty())
          throw InvalidArgument(name + ": at character " + std::to_string(i + 1) + ": a ring outside a polygon's "
                                "parentheses");
        add_ring(set, std::move(ring), name);
      }
      ring.clear();
      --depth;
    } else if (depth > 0 && (std::isdigit(static_cast<unsigned char>(c)) || c == '-' || c == '+' || c == '.')) {
      char* end = nullptr;
      const double x = std::strtod(text.c_str() + i, &end);
      char* end2 = nullptr;
      const double y = std::strtod(end, &end2);
      if (end2 == end) throw InvalidArgument(name + ": at character " + std::to_string(i + 1) + ": a vertex needs x and y");
      ring.push_back({x, y});
      i = static_cast<std::size_t>(end2 - text.c_str());
      while (i < text.size() && text[i] != ',' && text[i] != ')') ++i;  // a z or m value
      if (i < text.size() && text[i] == ')') --i;
    }
  }
  if (depth != 0) throw InvalidArgument(name + ": unbalanced parentheses in the WKT");
}

}  // namespace

PolygonSet parse_polygons(const std::string& text, const std::string& name) {
  PolygonSet set;
  const auto first = text.find_first_not_of(" \t\r\n");
  if (first != std::string::npos && text[first] == '{') {
    nlohmann::json j;
    try {
      j = nlohmann::json::parse(text);
      geometry_from_json(set, j, name);
    } catch (const nlohmann::json::exception& e) {
      throw InvalidArgument(name + ": not a GeoJSON polygon: " + e.what());
    }
  } else {
    polygons_from_wkt(set, text, name);
  }
  std::erase_if(set.polygons, [](const auto& polygon) { return polygon.empty(); });
  if (set.polygons.empty()) throw InvalidArgument(name + ": no polygon in it");
  return set;
}

PolygonSet read_polygons(const std::string& path) {
  // A regular file of bounded size: a device or a FIFO named here (/dev/zero) would
  // never end, and a polygon file is text a person wrote or exported.
  constexpr std::uintmax_t kMaxPolygonFileBytes = std::uintmax_t{256} << 20;
  std::error_code error;
  if (!std::filesystem::is_regular_file(path, error))
    throw InvalidArgument(path + ": not a regular file (a polygon file is GeoJSON or WKT text)");
  const std::uintmax_t size = std::filesystem::file_size(path, error);
  if (error || size > kMaxPolygonFileBytes)
    throw InvalidArgument(path + ": " + (error ? "cannot read its size" : "more than 256 MiB of polygon text"));
  std::ifstream in(path, std::ios::binary);
  if (!in) throw IoError(path + ": cannot open");
  std::string text(static_cast<std::size_t>(size), '\0');
  if (!in.read(text.data(), static_cast<std::streamsize>(size))) throw IoError(path + ": cannot read");
  return parse_polygons(text, path);
}

std::vector<bool> inside_box(std::span<const double> xyz, const CropBox& box) {
  std::vector<bool> keep(xyz.size() / 3);
  for (std::size_t i = 0; i < keep.size(); ++i) keep[i] = box.contains(&xyz[3 * i]);
  return keep;
}

std::vector<bool> inside_polygons(std::span<const double> xyz, const PolygonSet& polygons) {
  std::vector<bool> keep(xyz.size() / 3);
  for (std::size_t i = 0; i < keep.size(); ++i) keep[i] = polygons.contains(xyz[3 * i], xyz[3 * i + 1]);
  return keep;
}

}  // namespace vola::filters
