// GeoTIFF rasters written through GDAL: a MEM dataset over the computed cells, copied by
// the COG driver into GDAL's in-memory file system, whose bytes the caller writes to the
// final path through its temporary file (GDAL never opens a path of the user's).
#include <cpl_conv.h>
#include <cpl_string.h>
#include <cpl_vsi.h>
#include <gdal_priv.h>
#include <ogr_spatialref.h>

#include <string>
#include <vector>

#include "../reader_plugin.hpp"
#include "gdal_confined.hpp"
#include "gdal_memory.hpp"
#include "readers.hpp"
#include "vola/error.hpp"
#include "vola/geo/crs.hpp"

namespace vola::io {

std::vector<std::uint8_t> geotiff_with_gdal(const Raster& raster, const std::string& wkt, std::uint32_t epsg) {
  if (raster.width == 0 || raster.height == 0 || raster.values.size() != raster.width * raster.height ||
      raster.width * raster.height > kMaxRasterCells)
    throw InvalidArgument("GeoTIFF: a raster of " + std::to_string(raster.width) + " x " +
                          std::to_string(raster.height) + " cells with " + std::to_string(raster.values.size()) +
                          " values is not written");
  register_gdal_drivers();
  QuietGdalErrors quiet;
  const ConfinedGdalConfig confined;  // no sidecar files, no network, as for reading
  GDALDriver* mem = GetGDALDriverManager()->GetDriverByName("MEM");
  GDALDriver* cog = GetGDALDriverManager()->GetDriverByName("COG");
  if (!mem || !cog) throw IoError("GeoTIFF: this GDAL has no MEM or COG driver");

  // The sizes fit an int: at most kMaxRasterCells (2^28) cells.
  const int width = static_cast<int>(raster.width), height = static_cast<int>(raster.height);
  Dataset source(mem->Create("", width, height, 1, GDT_Float32, nullptr));
  if (!source) throw IoError(gdal_message("GeoTIFF: GDAL cannot hold the raster in memory"));
  GDALRasterBand* band = source->GetRasterBand(1);
  if (band->RasterIO(GF_Write, 0, 0, width, height, const_cast<float*>(raster.values.data()), width, height,
                     GDT_Float32, 0, 0) != CE_None)
    throw IoError(gdal_message("GeoTIFF: cannot fill the raster"));
  band->SetNoDataValue(kRasterNodata);
  band->SetDescription(raster_product_name(raster.product));
  double gt[6];
  for (int i = 0; i < 6; ++i) gt[i] = raster.geotransform[static_cast<std::size_t>(i)];
  source->SetGeoTransform(gt);
  if (const std::string named = geo::crs_file_reference(wkt); !named.empty())
    throw InvalidArgument("GeoTIFF: the CRS embeds a PROJ string that names a file ('" + named.substr(0, 80) +
                          "'); GDAL could open it, so this CRS is refused");
  if (!wkt.empty() || epsg != 0) {
    OGRSpatialReference srs;
    srs.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
    // importFromWkt/importFromEPSG only: SetFromUserInput would also open files and URLs.
    const OGRErr error = wkt.empty() ? srs.importFromEPSG(static_cast<int>(epsg)) : srs.importFromWkt(wkt.c_str());
    if (error != OGRERR_NONE)
      throw InvalidArgument(gdal_message(wkt.empty()
                                             ? ("GeoTIFF: GDAL does not know EPSG:" + std::to_string(epsg)).c_str()
                                             : "GeoTIFF: GDAL cannot read the file's CRS WKT"));
    source->SetSpatialRef(&srs);
  }

  const MemoryFolder folder;
  const std::string name = folder.path() + "/raster.tif";
  Options options;
  options.set("COMPRESS", "DEFLATE").set("PREDICTOR", "YES").set("RESAMPLING", "AVERAGE").set("OVERVIEWS", "AUTO");
  Dataset written(cog->CreateCopy(name.c_str(), source.get(), FALSE, options.get(), nullptr, nullptr));
  if (!written) throw IoError(gdal_message("GeoTIFF: GDAL's COG driver failed"));
  written.reset();  // GDALClose: the last tiles and the header
  if (CPLGetLastErrorType() >= CE_Failure) throw IoError(gdal_message("GeoTIFF: GDAL's COG driver failed"));
  vsi_l_offset length = 0;
  const GByte* data = VSIGetMemFileBuffer(name.c_str(), &length, FALSE);
  if (!data) throw IoError("GeoTIFF: GDAL wrote no file");
  return std::vector<std::uint8_t>(data, data + length);
}

}  // namespace vola::io

// The plugin's entry point (reader_plugin.hpp).
extern "C" void vola_plugin_write_geotiff(const vola::io::Raster& raster, const std::string& wkt, std::uint32_t epsg,
                                          std::vector<std::uint8_t>& out, vola::plugin::PluginFailure& failure) {
  vola::plugin::capture_failure(failure, [&] { out = vola::io::geotiff_with_gdal(raster, wkt, epsg); });
}
static_assert(std::is_same_v<decltype(&vola_plugin_write_geotiff), vola::io::plugin::WriteGeotiffEntry>);
