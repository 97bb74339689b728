// Footprint layers: the loader's side of the gdal plugin's OGR writers
// (src/io/plugins/footprints_gdal.cpp).
#include "vola/io/footprints.hpp"

#include "reader_plugin.hpp"

namespace vola::io {

std::vector<std::uint8_t> footprints_geojson(const FootprintLayer& layer, const std::string& collection_members_json) {
  const auto entry = reinterpret_cast<plugin::FootprintsGeojsonEntry>(vola::plugin::plugin_symbol(
      "gdal", plugin::kFootprintsGeojsonSymbol, "writing the GeoJSON footprints of " + layer.name));
  std::vector<std::uint8_t> bytes;
  PluginFailure failure;
  entry(layer, collection_members_json, bytes, failure);
  vola::plugin::throw_failure(failure);
  return bytes;
}

std::vector<std::uint8_t> footprints_geopackage(const FootprintLayer& layer) {
  const auto entry = reinterpret_cast<plugin::FootprintsGeopackageEntry>(vola::plugin::plugin_symbol(
      "gdal", plugin::kFootprintsGeopackageSymbol, "writing the GeoPackage footprints of " + layer.name));
  std::vector<std::uint8_t> bytes;
  PluginFailure failure;
  entry(layer, bytes, failure);
  vola::plugin::throw_failure(failure);
  return bytes;
}

}  // namespace vola::io
