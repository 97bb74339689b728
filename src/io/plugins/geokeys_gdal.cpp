// The CRS of a GeoTIFF key directory that defines it by its parts instead of by an EPSG
// code (user-defined, 32767, projected or geographic types: the projection, datum,
// ellipsoid and parameters in other keys), as GDAL's GeoTIFF driver reads it. LAS files
// carry the key directory in their LASF_Projection records 34735-34737; here those
// records become the GeoKey tags of a 1 x 1 GeoTIFF in GDAL's in-memory file system,
// which GDAL opens (GeoTIFF driver only) and whose CRS it reports. So vola reads such
// keys exactly as GDAL (and PDAL, which uses GDAL's reading) do, and writes none of
// libgeotiff's key interpretation itself.
#include <cpl_vsi.h>
#include <gdal_priv.h>
#include <ogr_spatialref.h>
#include <proj.h>

#include <cstring>
#include <string>
#include <type_traits>
#include <vector>

#include "../reader_plugin.hpp"
#include "gdal_confined.hpp"
#include "gdal_memory.hpp"

namespace vola::io {
namespace {

using Bytes = std::vector<std::uint8_t>;

void put16(Bytes& b, std::uint16_t v) {
  b.insert(b.end(), {static_cast<std::uint8_t>(v), static_cast<std::uint8_t>(v >> 8)});
}
void put32(Bytes& b, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) b.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
}

// A little-endian TIFF of one 8-bit pixel whose tags 34735 (SHORT), 34736 (DOUBLE) and
// 34737 (ASCII) hold the records' bytes (the last two only when present).
Bytes geotiff_with_keys(const plugin::GeoKeyRecords& keys) {
  struct Tag {
    std::uint16_t id, type;
    std::uint32_t count;
    const std::vector<std::uint8_t>* data;  // nullptr: the value below, inline
    std::uint32_t value;
  };
  std::vector<Tag> tags = {{256, 3, 1, nullptr, 1}, {257, 3, 1, nullptr, 1}, {258, 3, 1, nullptr, 8},
                           {259, 3, 1, nullptr, 1}, {262, 3, 1, nullptr, 1}, {273, 4, 1, nullptr, 0},
                           {277, 3, 1, nullptr, 1}, {278, 3, 1, nullptr, 1}, {279, 4, 1, nullptr, 1}};
  tags.push_back({34735, 3, static_cast<std::uint32_t>(keys.directory.size() / 2), &keys.directory, 0});
  if (keys.doubles.size() >= 8)
    tags.push_back({34736, 12, static_cast<std::uint32_t>(keys.doubles.size() / 8), &keys.doubles, 0});
  if (!keys.ascii.empty()) tags.push_back({34737, 2, static_cast<std::uint32_t>(keys.ascii.size()), &keys.ascii, 0});
  const std::uint32_t data_at = 8 + 2 + 12 * static_cast<std::uint32_t>(tags.size()) + 4;
  Bytes blobs;
  std::vector<std::uint32_t> blob_at(tags.size(), 0);
  for (std::size_t i = 0; i < tags.size(); ++i) {
    if (!tags[i].data) continue;
    const std::size_t bytes = tags[i].type == 3    ? 2 * std::size_t{tags[i].count}
                              : tags[i].type == 12 ? 8 * std::size_t{tags[i].count}
                                                   : tags[i].count;
    if (bytes <= 4) {  // TIFF holds a value of 4 bytes or less in the entry itself
      std::uint32_t packed = 0;
      std::memcpy(&packed, tags[i].data->data(), bytes);
      blob_at[i] = packed;
      continue;
    }
    blob_at[i] = data_at + static_cast<std::uint32_t>(blobs.size());
    blobs.insert(blobs.end(), tags[i].data->begin(), tags[i].data->begin() + static_cast<std::ptrdiff_t>(bytes));
    if (blobs.size() % 2) blobs.push_back(0);  // TIFF values start on word boundaries
  }
  const std::uint32_t pixel_at = data_at + static_cast<std::uint32_t>(blobs.size());
  Bytes tiff = {'I', 'I', 42, 0};
  put32(tiff, 8);
  put16(tiff, static_cast<std::uint16_t>(tags.size()));
  for (std::size_t i = 0; i < tags.size(); ++i) {
    put16(tiff, tags[i].id);
    put16(tiff, tags[i].type);
    put32(tiff, tags[i].count);
    // Inline values: a SHORT sits in the low bytes of the field (little-endian); a short
    // record's bytes as they are (blob_at holds them).
    put32(tiff, tags[i].data ? blob_at[i] : (tags[i].id == 273 ? pixel_at : tags[i].value));
  }
  put32(tiff, 0);  // no next IFD
  tiff.insert(tiff.end(), blobs.begin(), blobs.end());
  tiff.push_back(0);  // the pixel
  return tiff;
}

// libgeotiff, asked by GDAL for a unit the keys name, creates PROJ contexts of its own,
// copies of PROJ's default context, which print PROJ's errors to stderr (a unit code PROJ
// does not know: laspy's simple1_3.las names 32632 as its linear unit). The library
// never prints, so the default context logs nothing while GDAL reads the keys.
class QuietProjDefaultContext {
 public:
  QuietProjDefaultContext() : previous_(proj_log_level(nullptr, PJ_LOG_TELL)) { proj_log_level(nullptr, PJ_LOG_NONE); }
  ~QuietProjDefaultContext() { proj_log_level(nullptr, previous_); }
  QuietProjDefaultContext(const QuietProjDefaultContext&) = delete;
  QuietProjDefaultContext& operator=(const QuietProjDefaultContext&) = delete;

 private:
  PJ_LOG_LEVEL previous_;
};

std::string geokeys_wkt_with_gdal(const plugin::GeoKeyRecords& keys) {
  // A directory is 4 shorts of header and 4 per key; an odd last byte is no short, and
  // GDAL reads the whole shorts of such a record.
  if (keys.directory.size() < 8) return {};
  register_gdal_drivers();
  const ConfinedGdalConfig confined;
  const QuietGdalErrors quiet;
  const QuietProjDefaultContext quiet_proj;
  const MemoryFolder folder;
  const std::string path = folder.path() + "/keys.tif";
  Bytes tiff = geotiff_with_keys(keys);
  VSILFILE* file = VSIFileFromMemBuffer(path.c_str(), tiff.data(), static_cast<vsi_l_offset>(tiff.size()), FALSE);
  if (!file) return {};
  VSIFCloseL(file);  // the buffer stays registered under `path` until unlinked
  std::string wkt;
  {
    const char* const drivers[] = {"GTiff", nullptr};
    const Dataset dataset(GDALDataset::Open(path.c_str(), GDAL_OF_RASTER | GDAL_OF_READONLY, drivers));
    const OGRSpatialReference* srs = dataset ? dataset->GetSpatialRef() : nullptr;
    if (srs && !srs->IsEmpty()) {
      const char* const options[] = {"FORMAT=WKT2_2019", nullptr};
      char* text = nullptr;
      if (srs->exportToWkt(&text, options) == OGRERR_NONE && text) wkt = text;
      CPLFree(text);
    }
  }
  VSIUnlink(path.c_str());
  return wkt;
}

}  // namespace
}  // namespace vola::io

extern "C" void vola_plugin_geokeys_wkt(const vola::io::plugin::GeoKeyRecords& keys, std::string& out,
                                        vola::plugin::PluginFailure& failure) {
  vola::plugin::capture_failure(failure, [&] { out = vola::io::geokeys_wkt_with_gdal(keys); });
}
static_assert(std::is_same_v<decltype(&vola_plugin_geokeys_wkt), vola::io::plugin::GeokeysWktEntry>);
