// The fuzz build has no plugin libraries: the tile index's code finds the PROJ entry
// points (src/geo/plugins/proj_crs.cpp) and the gdal plugin's footprint writers
// (src/io/plugins/footprints_gdal.cpp) linked into the fuzz program instead, so that
// its seeds can be indexes write_tile_index writes, GeoPackage and all.
#include <cstring>
#include <string>

#include "../../src/geo/proj_plugin.hpp"
#include "../../src/io/reader_plugin.hpp"
#include "vola/error.hpp"

extern "C" const vola::geo::plugin::ProjEntries* vola_plugin_proj_entries();
extern "C" void vola_plugin_footprints_geojson(const vola::io::FootprintLayer&, const std::string&,
                                               std::vector<std::uint8_t>&, vola::plugin::PluginFailure&);
extern "C" void vola_plugin_footprints_geopackage(const vola::io::FootprintLayer&, std::vector<std::uint8_t>&,
                                                  vola::plugin::PluginFailure&);

namespace vola::plugin {

void* plugin_symbol(const char* name, const char* symbol, const std::string& purpose) {
  if (std::strcmp(name, "proj") == 0 && std::strcmp(symbol, vola::geo::plugin::kProjEntriesSymbol) == 0)
    return reinterpret_cast<void*>(&vola_plugin_proj_entries);
  if (std::strcmp(name, "gdal") == 0 && std::strcmp(symbol, vola::io::plugin::kFootprintsGeojsonSymbol) == 0)
    return reinterpret_cast<void*>(&vola_plugin_footprints_geojson);
  if (std::strcmp(name, "gdal") == 0 && std::strcmp(symbol, vola::io::plugin::kFootprintsGeopackageSymbol) == 0)
    return reinterpret_cast<void*>(&vola_plugin_footprints_geopackage);
  throw IoError(purpose + ": no plugin " + name + " (" + symbol + ") in the fuzz build");
}

}  // namespace vola::plugin
