// Fuzz entry point of the DEM reader through GDAL (io::read_dem_with_gdal, what the GDAL
// plugin runs, compiled into this program): the first byte picks the file kind (GeoTIFF
// or an Esri ASCII grid: modulo 2), the rest is the file, written to a scratch file with
// that extension. Only vola::Error may escape; what parses must account for every cell
// (valid + invalid = width x height, at most kMaxDemCells) with finite heights, the
// lowest of them reported as the minimum.
//
// Rasters above 2^20 cells are skipped: a few header bytes may claim up to
// kMaxDemCells cells (a legitimately compressed raster can), which would make single
// runs take seconds and gigabytes without reaching new code.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <mutex>
#include <span>

#include <cpl_error.h>
#include <gdal.h>

#include "fuzz_seeds.hpp"
#include "scratch_file.hpp"
#include "vola/error.hpp"
#include "readers.hpp"  // src/io/plugins: the reader itself, not its plugin

namespace vola_fuzz {
const char* const kDemExtensions[2] = {"tif", "asc"};
}  // namespace vola_fuzz

namespace {
using vola_fuzz::check;

bool small_enough(const std::string& path) {
  static std::once_flag registered;
  std::call_once(registered, [] { GDALAllRegister(); });
  CPLPushErrorHandler(CPLQuietErrorHandler);
  GDALDatasetH dataset = GDALOpen(path.c_str(), GA_ReadOnly);
  CPLPopErrorHandler();
  if (!dataset) return true;  // read_dem refuses it: that path is wanted
  const std::uint64_t cells = static_cast<std::uint64_t>(GDALGetRasterXSize(dataset)) *
                              static_cast<std::uint64_t>(GDALGetRasterYSize(dataset));
  GDALClose(dataset);
  return cells <= (std::uint64_t{1} << 20);
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const std::string path =
      vola_fuzz::scratch_file("dem", vola_fuzz::kDemExtensions[data[0] % 2], std::span(data + 1, size - 1));
  if (!small_enough(path)) return 0;
  try {
    const vola::io::DemRaster dem = vola::io::read_dem_with_gdal(path, {});
    const std::uint64_t cells = dem.cells.size();
    check(dem.width * dem.height <= vola::io::kMaxDemCells);
    check(cells + dem.invalid_cells == dem.width * dem.height);
    double lowest = INFINITY;
    for (std::uint64_t i = 0; i < cells; ++i) {
      check(std::isfinite(dem.cells.xyz[3 * i + 2]));
      lowest = std::min(lowest, dem.cells.xyz[3 * i + 2]);
    }
    check(cells == 0 || lowest == dem.minimum);
  } catch (const vola::Error&) {
    ++vola_fuzz::stats().refused;
    return 0;
  }
  ++vola_fuzz::stats().parsed;
  return 0;
}
