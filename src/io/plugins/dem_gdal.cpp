#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <gdal_priv.h>
#include <limits>
#include <memory>
#include <ogr_spatialref.h>
#include <string>
#include <vector>

#include "vola/error.hpp"
#include "vola/geo/crs.hpp"
#include "../reader_plugin.hpp"
#include "gdal_confined.hpp"
#include "readers.hpp"
#include "vola/io/dem.hpp"

namespace vola::io {

namespace {

void crs_of(const GDALDataset& dataset, const std::string& path, DemRaster& dem) {
  const OGRSpatialReference* srs = dataset.GetSpatialRef();
  if (!srs) return;
  char* wkt = nullptr;
  if (srs->exportToWkt(&wkt) == OGRERR_NONE && wkt) dem.wkt = wkt;
  CPLFree(wkt);
  if (const std::string named = geo::crs_file_reference(dem.wkt); !named.empty())
    throw FormatError(path, std::nullopt,
                      "its CRS embeds a PROJ string that names a file ('" + named.substr(0, 80) +
                          "'); GDAL would open it, so this CRS is refused");
  OGRSpatialReference identified(*srs);
  identified.AutoIdentifyEPSG();
  const char* authority = identified.GetAuthorityName(nullptr);
  const char* code = identified.GetAuthorityCode(nullptr);
  if (authority && code && std::string(authority) == "EPSG") {
    char* end = nullptr;
    const unsigned long value = std::strtoul(code, &end, 10);
    if (end != code && *end == '\0' && value > 0 && value <= std::numeric_limits<std::uint32_t>::max())
      dem.epsg = static_cast<std::uint32_t>(value);
  }
}

// A colour image is not an elevation raster: its band 1 holds red, a palette index or
// a hue, which read as heights give a relief of the picture (PDAL's autzen-height.tif is
// an RGB rendering of heights, not heights). Grey and undeclared bands are read.
void refuse_colour_images(GDALDataset& dataset, const std::string& path) {
  const GDALColorInterp interpretation = dataset.GetRasterBand(1)->GetColorInterpretation();
  const bool colour = interpretation == GCI_RedBand || interpretation == GCI_PaletteIndex ||
                      interpretation == GCI_HueBand || interpretation == GCI_CyanBand ||
                      interpretation == GCI_YCbCr_YBand;
  if (colour)
    throw FormatError(path, std::nullopt,
                      std::string("band 1 is the ") + GDALGetColorInterpretationName(interpretation) + " band of a " +
                          std::to_string(dataset.GetRasterCount()) +
                          "-band colour image, not heights (an elevation raster's band 1 holds heights)");
}

}  // namespace

DemRaster read_dem_with_gdal(const std::string& path,
                             const std::function<void(std::uint64_t, std::uint64_t)>& progress) {
  register_gdal_drivers();
  QuietGdalErrors quiet;
  const ConfinedGdalConfig confined;  // gdal_confined.hpp: one local file, nothing else
  const Dataset dataset = open_confined_raster(path);
  if (dataset->GetRasterCount() < 1) throw FormatError(path, std::nullopt, "the raster has no band");
  refuse_colour_images(*dataset, path);
  check_raster_sizes(*dataset, path);

  DemRaster dem;
  dem.width = static_cast<std::uint64_t>(dataset->GetRasterXSize());
  dem.height = static_cast<std::uint64_t>(dataset->GetRasterYSize());
  if (dem.width * dem.height > kMaxDemCells)
    throw InvalidArgument(path + ": " + std::to_string(dem.width) + " x " + std::to_string(dem.height) +
                          " cells is more than " + std::to_string(kMaxDemCells) + "; crop or resample it first");
  crs_of(*dataset, path, dem);
  double gt[6];
  // Without a geotransform GDAL fills the identity: cell (i, j) is at (i, j). A raster
  // placed by ground control points instead has its CRS on them, not on the cells: read
  // as the identity, it came out in pixel units with no CRS and no word.
  if (dataset->GetGeoTransform(gt) != CE_None && dataset->GetGCPCount() > 0)
    throw FormatError(path, std::nullopt,
                      "the raster is placed by " + std::to_string(dataset->GetGCPCount()) +
                          " ground control points, not a geotransform; warp it onto a grid first (gdalwarp)");
  if (gt[2] == 0.0 && gt[4] == 0.0 && std::isfinite(gt[0]) && std::isfinite(gt[3])) {
    dem.lattice = std::array<double, 2>{gt[0], gt[3]};
    if (std::isfinite(gt[1]) && std::isfinite(gt[5]) && gt[1] != 0.0 && gt[5] != 0.0)
      dem.cell_size = std::array<double, 2>{std::abs(gt[1]), std::abs(gt[5])};
  }

  GDALRasterBand* band = dataset->GetRasterBand(1);
  int has_scale = 0, has_offset = 0;
  double scale = band->GetScale(&has_scale), offset = band->GetOffset(&has_offset);
  if (!has_scale) scale = 1.0;
  if (!has_offset) offset = 0.0;
  GDALRasterBand* mask = band->GetMaskBand();
  const bool all_valid = band->GetMaskFlags() == GMF_ALL_VALID;

  // Windows of at most a million cells: whole rows when they are short enough.
  constexpr std::uint64_t kWindowCells = std::uint64_t{1} << 20;
  const std::uint64_t window_width = std::min<std::uint64_t>(std::max<std::uint64_t>(dem.width, 1), kWindowCells);
  const std::uint64_t window_height = std::max<std::uint64_t>(1, kWindowCells / window_width);
  std::vector<double> values;
  std::vector<std::uint8_t> valid;
  double minimum = std::numeric_limits<double>::infinity();
  for (std::uint64_t row = 0; row < dem.height; row += window_height) {
    const std::uint64_t rows = std::min(window_height, dem.height - row);
    for (std::uint64_t column = 0; column < dem.width; column += window_width) {
      const std::uint64_t columns = std::min(window_width, dem.width - column);
      values.resize(rows * columns);
      // The sizes fit an int: the raster has at most kMaxDemCells cells.
      const int x_off = static_cast<int>(column), y_off = static_cast<int>(row);
      const int x_size = static_cast<int>(columns), y_size = static_cast<int>(rows);
      const std::string where = "rows " + std::to_string(row) + ".., columns " + std::to_string(column) + "..";
      if (band->RasterIO(GF_Read, x_off, y_off, x_size, y_size, values.data(), x_size, y_size, GDT_Float64, 0, 0) !=
          CE_None)
        throw FormatError(path, std::nullopt, gdal_message(("cannot read " + where).c_str()));
      if (!all_valid) {
        valid.resize(rows * columns);
        if (mask->RasterIO(GF_Read, x_off, y_off, x_size, y_size, valid.data(), x_size, y_size, GDT_Byte, 0, 0) !=
            CE_None)
          throw FormatError(path, std::nullopt, gdal_message(("cannot read the mask of " + where).c_str()));
      }
      for (std::uint64_t r = 0; r < rows; ++r)
        for (std::uint64_t c = 0; c < columns; ++c) {
          const std::uint64_t i = r * columns + c;
          const double z = values[i] * scale + offset;
          if ((!all_valid && valid[i] == 0) || !std::isfinite(z)) {
            ++dem.invalid_cells;
            continue;
          }
          const double px = static_cast<double>(column + c) + 0.5, py = static_cast<double>(row + r) + 0.5;
          dem.cells.xyz.push_back(gt[0] + px * gt[1] + py * gt[2]);
          dem.cells.xyz.push_back(gt[3] + px * gt[4] + py * gt[5]);
          dem.cells.xyz.push_back(z);
          minimum = std::min(minimum, z);
        }
    }
    if (progress) progress(row + rows, dem.height);
  }
  dem.minimum = dem.cells.size() ? minimum : 0.0;
  return dem;
}

}  // namespace vola::io

// The plugin's entry points (reader_plugin.hpp).
extern "C" {
const char* vola_plugin_version() { return vola::plugin::kPluginVersion; }
void vola_plugin_read_dem(const std::string& path, const std::function<void(std::uint64_t, std::uint64_t)>& progress,
                          vola::io::DemRaster& out, vola::plugin::PluginFailure& failure) {
  vola::plugin::capture_failure(failure, [&] { out = vola::io::read_dem_with_gdal(path, progress); });
}
}
static_assert(std::is_same_v<decltype(&vola_plugin_read_dem), vola::io::plugin::ReadDemEntry>);
