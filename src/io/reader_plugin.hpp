// The entry points of the plugins libvola_gdal.so (elevation rasters read, GeoTIFF
// rasters and footprint layers written, user-defined GeoTIFF keys read, through GDAL/OGR), libvola_assimp.so (meshes
// through Assimp), libvola_octomap.so (OctoMap .bt/.ot through liboctomap) and
// libvola_openvdb.so (.vdb through OpenVDB); see src/plugin/plugin.hpp for why they are plugins.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "../plugin/plugin.hpp"
#include "vola/io/dem.hpp"
#include "vola/io/export.hpp"
#include "vola/io/footprints.hpp"
#include "vola/io/input.hpp"
#include "vola/io/occupancy_maps.hpp"

namespace vola::io {

using vola::plugin::PluginFailure;

namespace plugin {

// Entry points, looked up by these names (extern "C", so unmangled).
using ReadDemEntry = void (*)(const std::string& path, const std::function<void(std::uint64_t, std::uint64_t)>& progress,
                              DemRaster& out, PluginFailure& failure);
using ReadMeshEntry = void (*)(const std::string& path, std::vector<Triangle>& out, PluginFailure& failure);
// The raster as a cloud-optimised GeoTIFF's bytes (write_geotiff in vola/io/export.hpp);
// the CRS from `wkt`, else EPSG `epsg`, none when wkt is empty and epsg 0.
using WriteGeotiffEntry = void (*)(const Raster& raster, const std::string& wkt, std::uint32_t epsg,
                                   std::vector<std::uint8_t>& out, PluginFailure& failure);
// Footprint layers as GeoJSON or GeoPackage bytes (vola/io/footprints.hpp).
using FootprintsGeojsonEntry = void (*)(const FootprintLayer& layer, const std::string& collection_members_json,
                                        std::vector<std::uint8_t>& out, PluginFailure& failure);
using FootprintsGeopackageEntry = void (*)(const FootprintLayer& layer, std::vector<std::uint8_t>& out,
                                           PluginFailure& failure);
// The CRS (WKT2) of a GeoTIFF key directory as GDAL reads it; "" when GDAL reads none.
// The three LASF_Projection records' bytes: 34735 (the directory), 34736 (doubles) and
// 34737 (ASCII), the last two empty when the file has none.
struct GeoKeyRecords {
  std::vector<std::uint8_t> directory, doubles, ascii;
};
using GeokeysWktEntry = void (*)(const GeoKeyRecords& keys, std::string& out, PluginFailure& failure);
inline constexpr const char* kGeokeysWktSymbol = "vola_plugin_geokeys_wkt";
inline constexpr const char* kFootprintsGeojsonSymbol = "vola_plugin_footprints_geojson";
inline constexpr const char* kFootprintsGeopackageSymbol = "vola_plugin_footprints_geopackage";
inline constexpr const char* kReadDemSymbol = "vola_plugin_read_dem";
inline constexpr const char* kWriteGeotiffSymbol = "vola_plugin_write_geotiff";
inline constexpr const char* kReadMeshSymbol = "vola_plugin_read_mesh";

// Maps (vola/io/occupancy_maps.hpp). The writers write the file at `temporary` (an
// OutputFile's temporary, which the caller commits); `shift` is added to every world
// coordinate before OctoMap's coordToKey.
using ReadOctomapEntry = void (*)(const std::string& path, bool attributes, VoxelGrid& out, PluginFailure& failure);
using WriteOctomapEntry = void (*)(const MapVoxels& voxels, bool binary, const Point& shift,
                                   const std::string& temporary, MapExportReport& report, PluginFailure& failure);
using ReadVdbEntry = void (*)(const std::string& path, const std::string& grid, bool attributes, VoxelGrid& out,
                              PluginFailure& failure);
using WriteVdbEntry = void (*)(const MapVoxels& voxels, const std::string& temporary, MapExportReport& report,
                               PluginFailure& failure);
inline constexpr const char* kReadOctomapSymbol = "vola_plugin_read_octomap";
inline constexpr const char* kWriteOctomapSymbol = "vola_plugin_write_octomap";
inline constexpr const char* kReadVdbSymbol = "vola_plugin_read_vdb";
inline constexpr const char* kWriteVdbSymbol = "vola_plugin_write_vdb";

}  // namespace plugin
}  // namespace vola::io
