// GDAL held to one local raster file. Left to itself GDAL opens whatever it recognises:
// a VRT saved as .tif that pulls other local files (or URLs) into the raster, /vsicurl/
// and the other /vsi paths that fetch over the network or open archives, sidecar files
// it finds next to the input, and its 200-odd drivers' parsers. And it trusts the sizes
// a file declares: a 300-byte GeoTIFF with a large block or many samples per pixel made
// it allocate 12-16.7 GB on the first read.
//
// So: a regular file only, never a /vsi path; the DEM drivers vola documents only (VRT
// and every other indirection driver left out); no directory listing, no .aux.xml, no
// network (thread-local configuration while the file is open and read); a dataset that
// would read any file besides the input is refused; and the cells and the block a read
// allocates are bounded by a fixed allowance plus a multiple of the file's size.
#pragma once

#include <gdal_priv.h>

#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace vola::io {

// GDAL's driver names: GeoTIFF, USGS ASCII DEM (.dem), Erdas Imagine (.img), Esri
// ASCII grids.
inline constexpr const char* kDemDrivers[] = {"GTiff", "USGSDEM", "HFA", "AAIGrid", nullptr};

// A raster may hold kDemCellAllowance + kDemCellsPerByte * file bytes cells (each valid
// cell becomes 24 bytes of points), and one block of band 1 (what GDAL allocates per
// read) kDemBlockAllowance + kDemBlockBytesPerByte * file bytes bytes. Compressed DEMs
// and sparse tiles hold many cells per byte; these leave room for them.
inline constexpr std::uint64_t kDemCellAllowance = std::uint64_t{1} << 24;
inline constexpr std::uint64_t kDemCellsPerByte = 256;
inline constexpr std::uint64_t kDemBlockAllowance = std::uint64_t{64} << 20;
inline constexpr std::uint64_t kDemBlockBytesPerByte = 256;

// GDALAllRegister, once per process (thread safe).
void register_gdal_drivers();

// GDAL reports through a global handler that prints; the library never prints, so
// errors are kept quiet while GDAL works and taken from CPLGetLastErrorMsg.
class QuietGdalErrors {
 public:
  QuietGdalErrors() {
    CPLPushErrorHandler(CPLQuietErrorHandler);
    CPLErrorReset();
  }
  ~QuietGdalErrors() { CPLPopErrorHandler(); }
  QuietGdalErrors(const QuietGdalErrors&) = delete;
  QuietGdalErrors& operator=(const QuietGdalErrors&) = delete;
};

// `what`, then ": " and GDAL's last error message when it has one.
std::string gdal_message(const char* what);

struct DatasetCloser {
  void operator()(GDALDataset* d) const { GDALClose(d); }
};
using Dataset = std::unique_ptr<GDALDataset, DatasetCloser>;

// Sets GDAL's configuration for reading one local file on this thread, and restores
// what was there before when it goes.
class ConfinedGdalConfig {
 public:
  ConfinedGdalConfig();
  ~ConfinedGdalConfig();
  ConfinedGdalConfig(const ConfinedGdalConfig&) = delete;
  ConfinedGdalConfig& operator=(const ConfinedGdalConfig&) = delete;

 private:
  std::vector<std::pair<std::string, std::string>> previous_;  // (key, value or "\0" for unset)
};

// Opens `path` read-only as a raster of kDemDrivers (a ConfinedGdalConfig must be alive).
// FormatError for a /vsi path or anything but a regular file, when no allowed driver
// reads it, or when it would read other files too.
Dataset open_confined_raster(const std::string& path);

// FormatError when the raster's cells, or a block of band 1 (all its samples when they
// are interleaved by pixel), are more than the file's size justifies (limits above).
void check_raster_sizes(GDALDataset& dataset, const std::string& path);

}  // namespace vola::io
