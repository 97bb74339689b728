// Helpers of the LAZ codec tests: a minimal LAS header reader (independent of the
// library's LAS reader), whole-file decoding through the codec's public calls, and a
// writer of small LAZ files.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "io_test_data.hpp"
#include "vola/io/laz.hpp"

namespace vola_laz_test {

using Bytes = std::vector<std::uint8_t>;

// What the tests need of a LAS/LAZ file (LAS 1.0-1.4 header fields).
struct LasFile {
  std::string name;
  Bytes bytes;
  std::uint8_t point_format = 0;  // without the compression bits
  std::uint16_t record_length = 0;
  std::uint32_t offset_to_points = 0;
  std::uint64_t point_count = 0;
  Bytes laszip;  // the laszip VLR payload (empty for LAS)
  std::uint64_t laszip_offset = 0;
};
LasFile read_las_file(const vola_io_test::fs::path& path);
LasFile parse_las_file(Bytes bytes, std::string name);

// Every record of a LAZ file, decoded chunk by chunk (with coordinates_only, as
// laz::decode_chunk gives them for coordinates alone).
Bytes decode_all(const LasFile& file, bool coordinates_only = false);
// The uncompressed point records of a LAS file.
Bytes las_records(const LasFile& file);

// A LAZ file image as the tests need it: a 227-byte LAS 1.2 header stand-in holding
// only the offsets the codec reads, the laszip VLR payload at `laszip_offset`, the
// chunk table offset, the chunks (of `chunk_points` records, the last one shorter) and
// the table. The record's chunk size becomes `chunk_points`, unless the chunks are of
// variable size (then their counts in the table follow `chunk_points`). Compressor
// 1: one stream of every record right at the point data, no table.
LasFile make_laz(vola::io::laz::LaszipInfo info, std::span<const std::uint8_t> records,
                 std::uint64_t chunk_points);

// An uncompressed LAS file of `records`: LAS 1.2 (formats 0-5) or 1.4 (6-10), scale 0.01.
Bytes las_file_bytes(std::uint8_t point_format, std::uint16_t record_length, std::span<const std::uint8_t> records);

// A whole LAZ file (a real LAS header, as other readers need) holding the records of
// the uncompressed LAS file `las`: its header and VLRs, plus the laszip VLR, point
// format | 0x80, chunks of `chunk_points` records and the chunk table; EVLRs dropped.
Bytes laz_from_las(const LasFile& las, std::uint32_t chunk_points);
// The same with the given items and compressor (1: one stream, no chunk table).
Bytes laz_from_las(const LasFile& las, std::uint32_t chunk_points, vola::io::laz::LaszipInfo info);

}  // namespace vola_laz_test
