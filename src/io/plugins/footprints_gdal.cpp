// Footprint layers written through OGR (vola/io/footprints.hpp): the GeoJSON driver with
// RFC7946=YES (it reprojects to WGS84 itself) and the GPKG driver, each into GDAL's
// in-memory file system, whose bytes the caller writes through its temporary file.
#include <cpl_conv.h>
#include <gdal_priv.h>
#include <ogr_geometry.h>
#include <ogr_spatialref.h>
#include <ogrsf_frmts.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <type_traits>
#include <variant>
#include <vector>

#include "../reader_plugin.hpp"
#include "gdal_confined.hpp"
#include "gdal_memory.hpp"
#include "readers.hpp"
#include "vola/error.hpp"
#include "vola/geo/crs.hpp"

namespace vola::io {

namespace {

using Type = FootprintField::Type;

// Sets one thread-local GDAL configuration option while alive.
class ScopedConfig {
 public:
  ScopedConfig(const char* key, const char* value) : key_(key) {
    const char* old = CPLGetThreadLocalConfigOption(key, nullptr);
    had_ = old != nullptr;
    if (old) old_ = old;
    CPLSetThreadLocalConfigOption(key, value);
  }
  ~ScopedConfig() { CPLSetThreadLocalConfigOption(key_, had_ ? old_.c_str() : nullptr); }
  ScopedConfig(const ScopedConfig&) = delete;
  ScopedConfig& operator=(const ScopedConfig&) = delete;

 private:
  const char* key_;
  bool had_ = false;
  std::string old_;
};

// The layer's CRS, or none when it has none or GDAL cannot read its WKT (the footprints
// are then written as in no CRS: nowhere true to place them).
std::unique_ptr<OGRSpatialReference> spatial_reference(const std::string& wkt) {
  if (wkt.empty()) return nullptr;
  if (const std::string named = geo::crs_file_reference(wkt); !named.empty())
    throw InvalidArgument("footprints: the CRS embeds a PROJ string that names a file ('" + named.substr(0, 80) +
                          "'); GDAL would open it to place the footprints, so this CRS is refused");
  auto srs = std::make_unique<OGRSpatialReference>();
  srs->SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
  // importFromWkt only: SetFromUserInput would also open files and URLs.
  if (srs->importFromWkt(wkt.c_str()) != OGRERR_NONE) return nullptr;
  return srs;
}

// The transformation that takes the CRS to WGS84, or none when OGR has none (an
// engineering or unknown datum).
std::unique_ptr<OGRCoordinateTransformation> to_wgs84(const OGRSpatialReference& srs) {
  OGRSpatialReference wgs84;
  wgs84.SetWellKnownGeogCS("WGS84");
  wgs84.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
  return std::unique_ptr<OGRCoordinateTransformation>(OGRCreateCoordinateTransformation(&srs, &wgs84));
}

// Whether every corner of the footprint lands on a longitude and latitude. Under a
// geographic label on projected metres (x = 515393 "degrees") it does not, and OGR's
// RFC 7946 writer would cut the rectangle at the antimeridian into an empty polygon: such
// a feature is written with a null geometry instead, which RFC 7946 allows.
bool lands_in_wgs84(OGRCoordinateTransformation& transform, const Footprint& f) {
  double x[4] = {f.min_x, f.max_x, f.max_x, f.min_x};
  double y[4] = {f.min_y, f.min_y, f.max_y, f.max_y};
  int ok[4] = {0, 0, 0, 0};
  if (!transform.Transform(4, x, y, nullptr, ok)) return false;
  for (int i = 0; i < 4; ++i)
    if (!ok[i] || !(std::abs(x[i]) <= 180.0) || !(std::abs(y[i]) <= 90.0)) return false;
  return true;
}

OGRFieldType ogr_type(Type type) {
  switch (type) {
    case Type::integer: return OFTInteger64;
    case Type::real: return OFTReal;
    case Type::text: return OFTString;
    case Type::integer_list: return OFTInteger64List;
    case Type::real_list: return OFTRealList;
  }
  return OFTString;
}

std::string json_list(const std::vector<std::int64_t>& values) {
  std::string out = "[";
  for (std::size_t i = 0; i < values.size(); ++i) out += (i ? ", " : "") + std::to_string(values[i]);
  return out + "]";
}

std::string json_list(const std::vector<double>& values) {
  std::string out = "[";
  for (std::size_t i = 0; i < values.size(); ++i) out += (i ? ", " : "") + std::string(CPLSPrintf("%.17g", values[i]));
  return out + "]";
}

// The rectangle as a polygon, counter-clockwise (RFC 7946's right-hand rule), its edges
// cut into 8 segments so that a reprojection bends them as the CRS does.
std::unique_ptr<OGRPolygon> rectangle(const Footprint& f) {
  auto ring = std::make_unique<OGRLinearRing>();
  ring->addPoint(f.min_x, f.min_y);
  ring->addPoint(f.max_x, f.min_y);
  ring->addPoint(f.max_x, f.max_y);
  ring->addPoint(f.min_x, f.max_y);
  ring->addPoint(f.min_x, f.min_y);
  const double shorter = std::min(f.max_x - f.min_x, f.max_y - f.min_y);
  if (shorter > 0) ring->segmentize(shorter / 8);
  auto polygon = std::make_unique<OGRPolygon>();
  polygon->addRingDirectly(ring.release());
  return polygon;
}

// Fills `layer` (fields made by `create_fields`); lists as lists, or as JSON text when
// the driver has no list types. Geometries when `geometry`, but where `placed_by` (when
// given) cannot take a footprint to WGS84.
void fill(OGRLayer& out, const FootprintLayer& layer, bool lists_as_text, bool geometry,
          OGRCoordinateTransformation* placed_by = nullptr) {
  for (const FootprintField& field : layer.fields) {
    const bool list = field.type == Type::integer_list || field.type == Type::real_list;
    OGRFieldDefn definition(field.name.c_str(), list && lists_as_text ? OFTString : ogr_type(field.type));
    if (out.CreateField(&definition) != OGRERR_NONE)
      throw IoError(gdal_message(("footprints: cannot add the field " + field.name).c_str()));
  }
  for (const Footprint& f : layer.features) {
    if (f.values.size() != layer.fields.size())
      throw InvalidArgument("footprints: a feature has " + std::to_string(f.values.size()) + " values for " +
                            std::to_string(layer.fields.size()) + " fields");
    OGRFeature feature(out.GetLayerDefn());
    for (std::size_t i = 0; i < f.values.size(); ++i) {
      const int at = static_cast<int>(i);
      std::visit(
          [&](const auto& v) {
            using V = std::decay_t<decltype(v)>;
            if constexpr (std::is_same_v<V, std::int64_t>) feature.SetField(at, static_cast<GIntBig>(v));
            else if constexpr (std::is_same_v<V, double>) feature.SetField(at, v);
            else if constexpr (std::is_same_v<V, std::string>) feature.SetField(at, v.c_str());
            else if (lists_as_text) feature.SetField(at, json_list(v).c_str());
            else if constexpr (std::is_same_v<V, std::vector<std::int64_t>>)
              feature.SetField(at, static_cast<int>(v.size()), reinterpret_cast<const GIntBig*>(v.data()));
            else feature.SetField(at, static_cast<int>(v.size()), v.data());
          },
          f.values[i]);
    }
    if (geometry && (!placed_by || lands_in_wgs84(*placed_by, f))) feature.SetGeometryDirectly(rectangle(f).release());
    if (out.CreateFeature(&feature) != OGRERR_NONE)
      throw IoError(gdal_message("footprints: OGR cannot write a feature"));
  }
}

std::vector<std::uint8_t> bytes_of(const std::string& name) {
  vsi_l_offset length = 0;
  const GByte* data = VSIGetMemFileBuffer(name.c_str(), &length, FALSE);
  if (!data) throw IoError("footprints: GDAL wrote no file");
  return std::vector<std::uint8_t>(data, data + length);
}

GDALDriver& driver(const char* name) {
  register_gdal_drivers();
  GDALDriver* d = GetGDALDriverManager()->GetDriverByName(name);
  if (!d) throw IoError(std::string("footprints: this GDAL has no ") + name + " driver");
  return *d;
}

}  // namespace

std::vector<std::uint8_t> footprints_geojson_with_ogr(const FootprintLayer& layer,
                                                      const std::string& collection_members_json) {
  GDALDriver& geojson = driver("GeoJSON");
  QuietGdalErrors quiet;
  const std::unique_ptr<OGRSpatialReference> srs = spatial_reference(layer.crs_wkt);
  // A geocentric CRS's x and y are no map position (a rectangle of them lies across the
  // equatorial plane): its footprints have no RFC 7946 geometry.
  const std::unique_ptr<OGRCoordinateTransformation> transform = srs && !srs->IsGeocentric() ? to_wgs84(*srs) : nullptr;
  const bool placed = transform != nullptr;
  const MemoryFolder folder;
  const std::string name = folder.path() + "/footprints.geojson";
  {
    Dataset dataset(geojson.Create(name.c_str(), 0, 0, 0, GDT_Unknown, nullptr));
    if (!dataset) throw IoError(gdal_message("footprints: GDAL cannot create GeoJSON"));
    Options options;
    options.set("RFC7946", "YES").set("WRITE_NAME", "NO");
    if (!collection_members_json.empty())
      options.set("NATIVE_DATA", collection_members_json.c_str()).set("NATIVE_MEDIA_TYPE", "application/vnd.geo+json");
    OGRLayer* out = dataset->CreateLayer(layer.name.c_str(), placed ? srs.get() : nullptr,
                                         placed ? wkbPolygon : wkbNone, options.get());
    if (!out) throw IoError(gdal_message("footprints: GDAL cannot create the GeoJSON layer"));
    fill(*out, layer, false, placed, transform.get());
  }
  if (CPLGetLastErrorType() >= CE_Failure) throw IoError(gdal_message("footprints: GDAL's GeoJSON driver failed"));
  return bytes_of(name);
}

std::vector<std::uint8_t> footprints_geopackage_with_ogr(const FootprintLayer& layer) {
  GDALDriver& gpkg = driver("GPKG");
  QuietGdalErrors quiet;
  // The file's timestamps (gpkg_contents.last_change), fixed so that equal layers give
  // equal bytes.
  const ScopedConfig fixed_date("OGR_CURRENT_DATE", "2000-01-01T00:00:00.000Z");
  std::unique_ptr<OGRSpatialReference> srs = spatial_reference(layer.crs_wkt);
  if (!srs) {
    // Without one, OGR would record GeoPackage's "undefined geographic" CRS, and a GIS
    // would read the coordinates as degrees: a local engineering CRS says "unknown".
    srs = std::make_unique<OGRSpatialReference>();
    srs->SetLocalCS("unknown (the points stated no CRS)");
  }
  const MemoryFolder folder;
  const std::string name = folder.path() + "/footprints.gpkg";
  {
    Dataset dataset(gpkg.Create(name.c_str(), 0, 0, 0, GDT_Unknown, nullptr));
    if (!dataset) throw IoError(gdal_message("footprints: GDAL cannot create a GeoPackage"));
    OGRLayer* out = dataset->CreateLayer(layer.name.c_str(), srs.get(), wkbPolygon, nullptr);
    if (!out) throw IoError(gdal_message("footprints: GDAL cannot create the GeoPackage layer"));
    if (out->StartTransaction() != OGRERR_NONE) throw IoError(gdal_message("footprints: GeoPackage transaction"));
    fill(*out, layer, true, true);
    if (out->CommitTransaction() != OGRERR_NONE) throw IoError(gdal_message("footprints: GeoPackage commit"));
  }
  if (CPLGetLastErrorType() >= CE_Failure) throw IoError(gdal_message("footprints: GDAL's GPKG driver failed"));
  return bytes_of(name);
}

}  // namespace vola::io

// The plugin's entry points (reader_plugin.hpp).
extern "C" void vola_plugin_footprints_geojson(const vola::io::FootprintLayer& layer, const std::string& members,
                                               std::vector<std::uint8_t>& out, vola::plugin::PluginFailure& failure) {
  vola::plugin::capture_failure(failure, [&] { out = vola::io::footprints_geojson_with_ogr(layer, members); });
}
static_assert(std::is_same_v<decltype(&vola_plugin_footprints_geojson), vola::io::plugin::FootprintsGeojsonEntry>);

extern "C" void vola_plugin_footprints_geopackage(const vola::io::FootprintLayer& layer, std::vector<std::uint8_t>& out,
                                                  vola::plugin::PluginFailure& failure) {
  vola::plugin::capture_failure(failure, [&] { out = vola::io::footprints_geopackage_with_ogr(layer); });
}
static_assert(std::is_same_v<decltype(&vola_plugin_footprints_geopackage),
                             vola::io::plugin::FootprintsGeopackageEntry>);
