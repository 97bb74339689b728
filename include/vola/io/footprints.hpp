// Footprint layers (one rectangle per feature, with fields) written through OGR, for the
// GIS tools that open them: `vola tile`'s index as GeoJSON (RFC 7946: WGS84 longitude and
// latitude, which QGIS and ogrinfo place right whatever the survey's CRS) and as a
// GeoPackage in the survey's own CRS (its WKT, even one with no EPSG code).
#pragma once

#include <cstdint>
#include <string>
#include <variant>
#include <vector>

namespace vola::io {

struct FootprintField {
  enum class Type { integer, real, text, integer_list, real_list };
  std::string name;
  Type type = Type::integer;
};

// One value per field, of the field's type (integer_list: std::vector<std::int64_t>).
using FootprintValue =
    std::variant<std::int64_t, double, std::string, std::vector<std::int64_t>, std::vector<double>>;

struct Footprint {
  double min_x = 0, min_y = 0, max_x = 0, max_y = 0;  // in the layer's CRS
  std::vector<FootprintValue> values;                  // one per field, in order
};

struct FootprintLayer {
  std::string name;
  std::string crs_wkt;  // the footprints' CRS; empty: none known
  std::vector<FootprintField> fields;
  std::vector<Footprint> features;
};

// RFC 7946 GeoJSON bytes: each footprint's edges densified in the layer's CRS (so that
// the polygon follows the projected rectangle's curved edges) and reprojected to WGS84
// longitude/latitude (7 decimals, about 1 cm); the members of `collection_members_json`
// (a JSON object) written at the FeatureCollection's top level. Without a CRS, or one
// GDAL cannot read or take to WGS84, the geometries are null (nowhere true to put them);
// so is each footprint whose corners land on no longitude and latitude (a geographic
// label on projected coordinates).
std::vector<std::uint8_t> footprints_geojson(const FootprintLayer& layer, const std::string& collection_members_json);

// GeoPackage bytes: the footprints in the layer's own CRS (without one, a local
// engineering CRS named unknown, never GeoPackage's "undefined geographic");
// list fields become JSON text. Equal layers give equal bytes (the file's timestamps are
// fixed).
std::vector<std::uint8_t> footprints_geopackage(const FootprintLayer& layer);

}  // namespace vola::io
