// Digital elevation models through GDAL (GeoTIFF and every raster GDAL reads): band 1,
// one point per valid cell at its centre and height.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>

#include "vola/builder.hpp"

namespace vola::io {

// Rasters with more cells are refused (compressed files can claim any size).
inline constexpr std::uint64_t kMaxDemCells = std::uint64_t{1} << 28;

struct DemRaster {
  PointCloud cells;                   // x y height of each valid cell's centre
  std::uint64_t width = 0, height = 0;
  std::uint64_t invalid_cells = 0;    // nodata, masked or not finite
  double minimum = 0.0;               // lowest valid height (0 when none)
  std::optional<std::uint32_t> epsg;  // when GDAL identifies the CRS as an EPSG code
  std::string wkt;                    // the raster's CRS, empty when it has none
  // A corner of the cells of a north-up raster (the geotransform's origin), so that a grid
  // of voxels can line up with them; nullopt for a rotated raster.
  std::optional<std::array<double, 2>> lattice;
  // The cells' width and height (positive) of a north-up raster; nullopt when rotated.
  std::optional<std::array<double, 2>> cell_size;
};

// Cell centres through the geotransform (rotation terms included), heights through the
// band's scale and offset; invalid cells per GDAL's mask band (nodata, alpha, masks).
// Throws FormatError with GDAL's message when GDAL cannot read the file.
DemRaster read_dem(const std::string& path, const std::function<void(std::uint64_t, std::uint64_t)>& progress = {});

}  // namespace vola::io
