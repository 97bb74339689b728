#include "gdal_confined.hpp"

#include <cpl_conv.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <mutex>

#include "vola/error.hpp"

namespace vola::io {

namespace {

// (option, value) while a DEM is open.
constexpr std::pair<const char*, const char*> kConfinement[] = {
    // No listing of the input's directory, hence no sibling files (.ovr, .msk, .aux,
    // .prj, world files) found and opened.
    {"GDAL_DISABLE_READDIR_ON_OPEN", "EMPTY_DIR"},
    // No .aux.xml read (or written) beside the input.
    {"GDAL_PAM_ENABLED", "NO"},
    // /vsicurl/ tests only names with these extensions: none that exists.
    {"CPL_VSIL_CURL_ALLOWED_EXTENSIONS", ".vola-no-network"},
    {"GDAL_HTTP_MAX_RETRY", "0"},
    {"GDAL_HTTP_TIMEOUT", "1"},
};

bool starts_with_vsi(const std::string& path) {
  if (path.size() < 4) return false;
  std::string head = path.substr(0, 4);
  std::transform(head.begin(), head.end(), head.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return head == "/vsi";
}

std::uint64_t file_bytes(const std::string& path) {
  std::error_code error;
  const std::uint64_t bytes = std::filesystem::file_size(path, error);
  if (error) throw IoError("cannot read the size of " + path + ": " + error.message());
  return bytes;
}

// Every file GDAL would read for the dataset must be the input itself.
void check_reads_only(GDALDataset& dataset, const std::string& path) {
  char** files = dataset.GetFileList();
  std::string other;
  for (char** f = files; f && *f && other.empty(); ++f) {
    std::error_code error;
    if (!std::filesystem::equivalent(*f, path, error) || error) other = *f;
  }
  CSLDestroy(files);
  if (!other.empty())
    throw FormatError(path, std::nullopt,
                      "GDAL would also read '" + other + "' for this raster; only the given file is read");
}

}  // namespace

void register_gdal_drivers() {
  static std::once_flag registered;
  std::call_once(registered, [] { GDALAllRegister(); });
}

std::string gdal_message(const char* what) {
  const char* message = CPLGetLastErrorMsg();
  return std::string(what) + (message && *message ? std::string(": ") + message : std::string());
}

ConfinedGdalConfig::ConfinedGdalConfig() {
  for (const auto& [key, value] : kConfinement) {
    const char* old = CPLGetThreadLocalConfigOption(key, nullptr);
    previous_.emplace_back(key, old ? std::string(old) : std::string(1, '\0'));
    CPLSetThreadLocalConfigOption(key, value);
  }
}

ConfinedGdalConfig::~ConfinedGdalConfig() {
  for (const auto& [key, value] : previous_)
    CPLSetThreadLocalConfigOption(key.c_str(), value == std::string(1, '\0') ? nullptr : value.c_str());
}

Dataset open_confined_raster(const std::string& path) {
  if (starts_with_vsi(path))
    throw FormatError(path, std::nullopt, "GDAL's virtual file systems (/vsi...) are not opened; give a local file");
  std::error_code error;
  if (!std::filesystem::is_regular_file(path, error))
    throw FormatError(path, std::nullopt, "not a regular file (a directory, a device, or a name that does not exist)");
  Dataset dataset(GDALDataset::FromHandle(
      GDALOpenEx(path.c_str(), GDAL_OF_RASTER | GDAL_OF_READONLY, kDemDrivers, nullptr, nullptr)));
  if (!dataset) {
    const char* message = CPLGetLastErrorMsg();
    throw FormatError(path, std::nullopt,
                      std::string("no DEM driver reads it (GeoTIFF, USGS DEM, Erdas Imagine, Esri ASCII grid; "
                                  "VRT and other formats are not opened)") +
                          (message && *message ? std::string(": ") + message : std::string()));
  }
  check_reads_only(*dataset, path);
  return dataset;
}

void check_raster_sizes(GDALDataset& dataset, const std::string& path) {
  const std::uint64_t bytes = file_bytes(path);
  const std::uint64_t width = static_cast<std::uint64_t>(std::max(dataset.GetRasterXSize(), 0));
  const std::uint64_t height = static_cast<std::uint64_t>(std::max(dataset.GetRasterYSize(), 0));
  const std::uint64_t cell_limit = kDemCellAllowance + kDemCellsPerByte * bytes;
  if (width * height > cell_limit)
    throw FormatError(path, std::nullopt,
                      "declares " + std::to_string(width) + " x " + std::to_string(height) + " cells, more than the " +
                          std::to_string(cell_limit) + " a file of " + std::to_string(bytes) + " bytes may hold here");
  GDALRasterBand* band = dataset.GetRasterBand(1);
  int block_x = 0, block_y = 0;
  band->GetBlockSize(&block_x, &block_y);
  const char* interleave = dataset.GetMetadataItem("INTERLEAVE", "IMAGE_STRUCTURE");
  const bool by_pixel = interleave && std::string(interleave) == "PIXEL";
  const std::uint64_t samples = by_pixel ? static_cast<std::uint64_t>(dataset.GetRasterCount()) : 1;
  const std::uint64_t block = static_cast<std::uint64_t>(std::max(block_x, 0)) *
                              static_cast<std::uint64_t>(std::max(block_y, 0)) *
                              static_cast<std::uint64_t>(GDALGetDataTypeSizeBytes(band->GetRasterDataType())) * samples;
  const std::uint64_t block_limit = kDemBlockAllowance + kDemBlockBytesPerByte * bytes;
  if (block > block_limit)
    throw FormatError(path, std::nullopt,
                      "a block of " + std::to_string(block_x) + " x " + std::to_string(block_y) + " cells" +
                          (samples > 1 ? " x " + std::to_string(samples) + " samples" : std::string()) + " takes " +
                          std::to_string(block) + " bytes to read, more than the " + std::to_string(block_limit) +
                          " a file of " + std::to_string(bytes) + " bytes may ask for here");
}

}  // namespace vola::io
