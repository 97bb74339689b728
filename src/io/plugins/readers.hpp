// The readers (and the GeoTIFF and map writers) inside the plugins, as plain functions: what the
// plugins' entry points run, and what the fuzz targets call directly (linked with GDAL
// or Assimp themselves).
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "vola/io/dem.hpp"
#include "vola/io/export.hpp"
#include "vola/io/footprints.hpp"
#include "vola/io/input.hpp"
#include "vola/io/occupancy_maps.hpp"

namespace vola::io {

// As read_dem (vola/io/dem.hpp), through GDAL in this process.
DemRaster read_dem_with_gdal(const std::string& path, const std::function<void(std::uint64_t, std::uint64_t)>& progress);
// The GeoTIFF bytes of write_geotiff (vola/io/export.hpp), through GDAL in this process:
// the CRS from `wkt`, else EPSG `epsg`, none when wkt is empty and epsg 0.
std::vector<std::uint8_t> geotiff_with_gdal(const Raster& raster, const std::string& wkt, std::uint32_t epsg);
// The bytes of footprints_geojson / footprints_geopackage (vola/io/footprints.hpp),
// through OGR in this process.
std::vector<std::uint8_t> footprints_geojson_with_ogr(const FootprintLayer& layer,
                                                      const std::string& collection_members_json);
std::vector<std::uint8_t> footprints_geopackage_with_ogr(const FootprintLayer& layer);
// As read_mesh_triangles (vola/io/mesh.hpp), through Assimp in this process.
std::vector<Triangle> read_mesh_with_assimp(const std::string& path);
// As read_octomap and write_octomap (vola/io/occupancy_maps.hpp), through liboctomap in
// this process: the file written at `temporary`, every world coordinate moved by `shift`.
VoxelGrid read_octomap_with_liboctomap(const std::string& path, bool attributes);
void write_octomap_with_liboctomap(const MapVoxels& voxels, bool binary, const Point& shift, const std::string& temporary,
                                   MapExportReport& report);
// As read_vdb and write_vdb, through OpenVDB in this process.
VoxelGrid read_vdb_with_openvdb(const std::string& path, const std::string& grid, bool attributes);
void write_vdb_with_openvdb(const MapVoxels& voxels, const std::string& temporary, MapExportReport& report);

}  // namespace vola::io
