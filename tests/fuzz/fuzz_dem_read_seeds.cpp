// Seeds for fuzz_dem_read: the small GeoTIFFs of the shared data folder (beside
// golden/), a 3 x 2 float32 GeoTIFF written here byte by byte (pixel scale, tie point,
// GDAL nodata tag) and Esri ASCII grids (corner and centre origins, nodata), each
// prefixed with its selector byte. Linked into fuzz_dem_read_replay in place of
// fuzz_seeds.cpp.
#include <algorithm>
#include <cstring>
#include <fstream>
#include <iterator>
#include <string>

#include "fuzz_seeds.hpp"

namespace vola_fuzz {

namespace {

using Bytes = std::vector<std::uint8_t>;
enum Kind : std::uint8_t { kTiff = 0, kAscii = 1 };  // fuzz_dem_read.cpp's kDemExtensions

Seed seed(const std::string& name, Kind kind, const Bytes& file) {
  Bytes bytes{kind};
  bytes.insert(bytes.end(), file.begin(), file.end());
  return {name, std::move(bytes)};
}

template <class T>
void put(Bytes& out, T value) {
  std::uint8_t raw[sizeof(T)];
  std::memcpy(raw, &value, sizeof(T));
  out.insert(out.end(), raw, raw + sizeof(T));
}

// Little-endian baseline TIFF, one strip of float32 heights, GeoTIFF scale and tie point.
Bytes geotiff() {
  const float heights[6] = {10.5f, 11.0f, -9999.0f, 12.25f, 13.0f, 9.75f};
  const double scale[3] = {2.0, 2.0, 0.0}, tie[6] = {0, 0, 0, 500000.0, 4000000.0, 0.0};
  const std::string nodata = "-9999";
  struct Entry {
    std::uint16_t tag, type;
    std::uint32_t count, value;
  };
  // Data after the IFD: heights, scale, tie point, nodata text.
  constexpr std::uint32_t kEntries = 13, kIfd = 8, kData = kIfd + 2 + kEntries * 12 + 4;
  const std::uint32_t at_scale = kData + sizeof heights, at_tie = at_scale + sizeof scale,
                      at_nodata = at_tie + sizeof tie;
  const Entry entries[kEntries] = {
      {256, 3, 1, 3},                                                   // width
      {257, 3, 1, 2},                                                   // height
      {258, 3, 1, 32},                                                  // bits per sample
      {259, 3, 1, 1},                                                   // no compression
      {262, 3, 1, 1},                                                   // black is zero
      {273, 4, 1, kData},                                               // strip offset
      {277, 3, 1, 1},                                                   // samples per pixel
      {278, 3, 1, 2},                                                   // rows per strip
      {279, 4, 1, sizeof heights},                                      // strip bytes
      {339, 3, 1, 3},                                                   // sample format: IEEE float
      {33550, 12, 3, at_scale},                                         // ModelPixelScale
      {33922, 12, 6, at_tie},                                           // ModelTiepoint
      {42113, 2, static_cast<std::uint32_t>(nodata.size() + 1), at_nodata},  // GDAL_NODATA
  };
  Bytes b{'I', 'I', 42, 0};
  put(b, kIfd);
  put(b, static_cast<std::uint16_t>(kEntries));
  for (const Entry& e : entries) {
    put(b, e.tag);
    put(b, e.type);
    put(b, e.count);
    if (e.type == 3 && e.count == 1) {  // a short sits in the first two bytes of the value
      put(b, static_cast<std::uint16_t>(e.value));
      put(b, std::uint16_t{0});
    } else {
      put(b, e.value);
    }
  }
  put(b, std::uint32_t{0});  // no next IFD
  for (float h : heights) put(b, h);
  for (double v : scale) put(b, v);
  for (double v : tie) put(b, v);
  b.insert(b.end(), nodata.begin(), nodata.end());
  b.push_back(0);
  return b;
}

Bytes text(const std::string& s) { return Bytes(s.begin(), s.end()); }

Bytes read_all(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return Bytes(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

}  // namespace

std::vector<Seed> synthetic_seeds() {
  return {seed("float32.tif", kTiff, geotiff()),
          seed("corner.asc", kAscii,
               text("ncols 4\nnrows 3\nxllcorner 100.0\nyllcorner 200.0\ncellsize 5\nNODATA_value -9999\n"
                    "1 2 3 4\n5 -9999 7 8\n9 10 11.5 12\n")),
          seed("centre.asc", kAscii, text("NCOLS 2\nNROWS 2\nXLLCENTER -3.5\nYLLCENTER 7\nCELLSIZE 0.5\n0 1e3\n-2 7\n"))};
}

// The shared data folder's DEM files of at most 64 KiB; `golden` is $VOLA_SHARED/golden.
std::vector<Seed> golden_seeds(const std::filesystem::path& golden) {
  std::vector<Seed> seeds;
  const auto dems = golden.parent_path() / "data" / "dem";
  if (!std::filesystem::is_directory(dems)) return seeds;
  for (const auto& entry : std::filesystem::directory_iterator(dems))
    if (entry.is_regular_file() && entry.path().extension() == ".tif" && entry.file_size() <= 64 * 1024)
      seeds.push_back(seed("dem_" + entry.path().filename().string(), kTiff, read_all(entry.path())));
  std::sort(seeds.begin(), seeds.end(), [](const Seed& a, const Seed& b) { return a.name < b.name; });
  return seeds;
}

}  // namespace vola_fuzz
