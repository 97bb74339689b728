// Internal to the LAZ codec: where each item sits in a point record, checked once per
// call so that the per-point loops only test flags. A record is one of the sequences
//   POINT10 [GPSTIME11] [RGB12] [WAVEPACKET13] [BYTE]    (compressors 1, 2; version 1
//                                                         or 2, wave packets version 1)
//   POINT14 [RGB14 | RGBNIR14] [WAVEPACKET14] [BYTE14]   (compressor 3; version 3 or 4)
// which are the layouts of LAS point formats 0-10 with extra bytes.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "vola/io/laz.hpp"

namespace vola::io::laz {

struct RecordLayout {
  bool layered = false;
  // Version 4 of the layered items fixes how they follow the scanner channel (see
  // layered_chunk.cpp); each item has its own version.
  bool point_v4 = false, rgb_v4 = false, wave_v4 = false, bytes_v4 = false;
  // Version 1 of the point-wise items (LASzip 1.x); each item has its own version.
  bool point_v1 = false, gps_v1 = false, rgb_v1 = false, bytes_v1 = false;
  bool any_v1() const { return point_v1 || gps_v1 || rgb_v1 || bytes_v1; }
  std::size_t length = 0;
  std::size_t gps_at = 0;    // 0 = none (point-wise only; layered records always have it)
  std::size_t rgb_at = 0;    // 0 = none
  bool nir = false;          // RGBNIR14: NIR after RGB
  std::size_t wave_at = 0;   // 0 = none: the wave packet (29 bytes)
  std::size_t bytes_at = 0;  // extra bytes
  std::size_t bytes = 0;
  bool operator==(const RecordLayout&) const = default;
};

// Throws FormatError(source, offset_of_items, ...) for unsupported item lists.
RecordLayout record_layout(const LaszipInfo& info, const std::string& source, std::uint64_t items_offset);

// Compressor 1 and 2 chunks: the first record raw, then one arithmetic stream. The
// decoders return how many bytes the arithmetic decoding wanted beyond the chunk (0
// for a sound chunk).
std::uint64_t decode_pointwise_chunk(const RecordLayout& layout, std::span<const std::uint8_t> chunk, std::uint64_t count,
                            std::uint8_t* records);
void encode_pointwise_chunk(const RecordLayout& layout, std::span<const std::uint8_t> records,
                            std::vector<std::uint8_t>& out);

// Compressor 3 chunks: the first record raw, the point count, every layer's size, then
// the layers. Throws FormatError(source, offset, ...) for inconsistent layer sizes.
// With xyz_only, only the XY and Z layers are decoded (see laz::decode_chunk).
std::uint64_t decode_layered_chunk(const RecordLayout& layout, std::span<const std::uint8_t> chunk, std::uint64_t count,
                          std::uint8_t* records, const std::string& where, std::uint64_t chunk_offset,
                          const std::string& source, bool xyz_only = false);
void encode_layered_chunk(const RecordLayout& layout, std::span<const std::uint8_t> records,
                          std::vector<std::uint8_t>& out);

}  // namespace vola::io::laz
