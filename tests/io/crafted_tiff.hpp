// Classic little-endian TIFF files built byte by byte, declaring whatever a test wants
// (sizes, samples, tiles) whatever data follows: hostile rasters a library would never
// write.
#pragma once

#include <algorithm>
#include <cstdint>
#include <utility>
#include <vector>

namespace vola_io_test {

struct TiffLayout {
  std::uint32_t width = 1, height = 1;
  std::uint16_t samples_per_pixel = 1;  // contiguous (PlanarConfiguration 1)
  std::uint16_t bits_per_sample = 32;   // IEEE float samples
  // Strips of rows_per_strip rows, or tiles of tile_side x tile_side when tile_side > 0.
  std::uint32_t rows_per_strip = 1;
  std::uint32_t tile_side = 0;
  // Offsets and byte counts of every strip or tile: 0 and 0 (sparse: GDAL reads nodata
  // without decoding), or, for a single strip, the file's own first piece_bytes bytes
  // (which GDAL must then read into a whole block).
  std::uint32_t piece_bytes = 0;
  // 1: none; 8: deflate (GDAL reads an uncompressed single strip line by line, a
  // compressed one as one block).
  std::uint16_t compression = 1;
};

inline std::vector<std::uint8_t> crafted_tiff(const TiffLayout& t) {
  std::vector<std::uint8_t> out{'I', 'I', 42, 0, 8, 0, 0, 0};
  const auto put = [&](std::uint64_t v, int bytes) {
    for (int i = 0; i < bytes; ++i) out.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
  };
  std::uint64_t pieces = 0;
  if (t.tile_side)
    pieces = std::uint64_t{(t.width + t.tile_side - 1) / t.tile_side} * ((t.height + t.tile_side - 1) / t.tile_side);
  else
    pieces = (t.height + t.rows_per_strip - 1) / t.rows_per_strip;
  // Entries (tag, type, count, value or offset); SHORT = 3, LONG = 4. The offsets and
  // byte counts arrays (all zero) follow the IFD when there is more than one piece.
  struct Entry {
    std::uint16_t tag, type;
    std::uint64_t count, value;
  };
  std::vector<Entry> entries = {{256, 4, 1, t.width},
                                {257, 4, 1, t.height},
                                {258, 3, 1, t.bits_per_sample},
                                {259, 3, 1, t.compression},
                                {262, 3, 1, 1},
                                {277, 3, 1, t.samples_per_pixel},
                                {284, 3, 1, 1},
                                {339, 3, 1, 3}};
  const std::uint64_t arrays_at = 8 + 2 + 12 * (entries.size() + (t.tile_side ? 4 : 3)) + 4;
  const std::uint64_t array = pieces == 1 ? 0 : arrays_at;
  const bool single_with_data = pieces == 1 && t.piece_bytes > 0;
  if (t.tile_side) {
    entries.push_back({322, 4, 1, t.tile_side});
    entries.push_back({323, 4, 1, t.tile_side});
    entries.push_back({324, 4, pieces, array});
    entries.push_back({325, 4, pieces, array});
  } else {
    entries.push_back({273, 4, pieces, single_with_data ? 8 : array});
    entries.push_back({278, 4, 1, t.rows_per_strip});
    entries.push_back({279, 4, pieces, single_with_data ? t.piece_bytes : array});
  }
  std::sort(entries.begin(), entries.end(), [](const Entry& a, const Entry& b) { return a.tag < b.tag; });
  put(entries.size(), 2);
  for (const Entry& e : entries) {
    put(e.tag, 2);
    put(e.type, 2);
    put(e.count, 4);
    put(e.value, 4);
  }
  put(0, 4);                                               // no next IFD
  if (pieces > 1) out.resize(out.size() + 4 * pieces, 0);  // one zero array serves both
  return out;
}

}  // namespace vola_io_test
