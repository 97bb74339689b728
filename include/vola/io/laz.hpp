// LAZ: LAS point records compressed by the LASzip scheme, decoded and encoded by vola's
// own codec (no LASzip or laz-perf library). What it covers:
//   - the "laszip encoded" VLR (user id "laszip encoded", record 22204);
//   - compressor 2 (point-wise chunked; point formats 0-5 as POINT10, GPSTIME11, RGB12
//     and BYTE items, version 2) and compressor 1 (the same items as one unchunked
//     stream);
//   - compressor 3 (layered chunked; formats 6-10 as POINT14, RGB14, RGBNIR14 and
//     BYTE14 items, versions 3 and 4), with empty layers and variable-size chunks
//     (COPC);
//   - the chunk table (its offset in the first 8 bytes of the point data, or, when that
//     offset is -1, in the last 8 bytes of the file).
// Not covered (refused with FormatError): item version 1 (LASzip 1.x), wave packets
// (WAVEPACKET13/14, formats 4, 5, 9, 10), a chunk table a writer never finished.
//
// Every malformed input throws vola::FormatError naming the chunk and byte offset;
// nothing reads outside the given spans or allocates from an unchecked count.
// Decoding is serial within a chunk (the arithmetic coder is); chunks are independent,
// so callers may decode chunks in parallel, each with its own call. Each thread keeps
// the coders of the last record layout it decoded or encoded (models are created on
// first use: ~0.4 MB decoding pdal_autzen_trim.laz; for point-wise records at most
// ~4 MB decoding, whose models carry look-up tables, and ~2 MB encoding), so that a
// file's many chunks reuse them instead of allocating models per chunk.
// Speed (one core, Release, bench/laz_decode.cpp, pdal_autzen_trim.laz): point format
// 3 decodes at ~5.3 M points/s, 2.5x laz-perf's WebAssembly build under node and ~1.65x
// LASzip's own C++ decoder (3.2 M points/s) on the same machine.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <vector>

namespace vola::io::laz {

// LASzip item types (the order of a record's parts).
enum ItemType : std::uint16_t {
  kByte = 0,
  kPoint10 = 6,
  kGpsTime11 = 7,
  kRgb12 = 8,
  kWavePacket13 = 9,
  kPoint14 = 10,
  kRgb14 = 11,
  kRgbNir14 = 12,
  kWavePacket14 = 13,
  kByte14 = 14,
};

struct Item {
  std::uint16_t type = 0, size = 0, version = 0;
  bool operator==(const Item&) const = default;
};

// "POINT10(20) version 2", for people.
std::string describe_item(const Item& item);

inline constexpr std::uint32_t kVariableChunkSize = 0xFFFFFFFFu;

// The laszip VLR. compressor: 1 point-wise, 2 point-wise chunked, 3 layered chunked;
// coder 0 = arithmetic (the only one); chunk_size kVariableChunkSize = each chunk's
// point count is in the chunk table.
struct LaszipInfo {
  std::uint16_t compressor = 2, coder = 0;
  std::uint8_t version_major = 3, version_minor = 4;
  std::uint16_t revision = 3;
  std::uint32_t options = 0;
  std::uint32_t chunk_size = 50000;
  std::int64_t special_evlr_count = -1, special_evlr_offset = -1;
  std::vector<Item> items;

  // Bytes of one point record (the items' sizes added).
  std::size_t record_length() const;
  bool operator==(const LaszipInfo&) const = default;
};

// Parses the VLR payload; throws FormatError (file `source`, offset payload_offset +
// the field's) on a short record, an unknown compressor/coder, or items that are not a
// supported sequence (see above) with their fixed sizes.
LaszipInfo parse_laszip_vlr(std::span<const std::uint8_t> payload, const std::string& source = {},
                            std::uint64_t payload_offset = 0);
std::vector<std::uint8_t> laszip_vlr_payload(const LaszipInfo& info);

// The record vola writes for LAS point format 0-3 (compressor 2) or 6-8 (compressor 3,
// item version 3) with `record_length` bytes per point (extra bytes = the rest).
// Throws InvalidArgument for other formats (wave packets) or a too short record.
LaszipInfo laszip_info_for(std::uint8_t point_format, std::uint16_t record_length);

// Where each chunk is in the file.
struct ChunkEntry {
  std::uint64_t point_count = 0, byte_offset = 0, byte_size = 0;
};

// Reads `n` bytes at file offset `offset` into `out` (throws when it cannot).
using ReadAt = std::function<void(std::uint64_t offset, std::uint64_t n, std::uint8_t* out)>;

// The chunks of a LAZ file's point data. offset_to_points is the LAS header's; the
// chunks must hold exactly `point_count` points and lie between the point data and the
// chunk table. Compressor 1 gives one chunk of every point (its size: the rest of the
// file). Throws FormatError (file `source`) when the table is missing or inconsistent.
std::vector<ChunkEntry> read_chunk_table(const LaszipInfo& info, const ReadAt& read_at, std::uint64_t file_size,
                                         std::uint64_t offset_to_points, std::uint64_t point_count,
                                         const std::string& source = {});

// The chunk table's bytes (version 0, count, then the coded counts and sizes) for the
// chunks in file order; its offset goes into the 8 bytes at the start of point data.
std::vector<std::uint8_t> chunk_table_bytes(const LaszipInfo& info, std::span<const ChunkEntry> chunks);

// Decodes one chunk (its bytes exactly, as the chunk table gives them) into `count`
// LAS point records of record_length bytes each (the bytes an uncompressed LAS file
// would hold). `chunk_index` and `chunk_offset` only name the chunk in errors.
// With xyz_only, a layered chunk (point formats 6-10) decodes only the layers X, Y and Z
// need (LASzip's selective decompression): the records' coordinates are exact, their
// other fields are not (they hold values of earlier points). Point-wise chunks (formats
// 0-5), whose items share one stream, are always decoded whole.
void decode_chunk(const LaszipInfo& info, std::span<const std::uint8_t> chunk, std::uint64_t count,
                  std::uint8_t* records, std::size_t record_length, std::uint64_t chunk_index = 0,
                  std::uint64_t chunk_offset = 0, const std::string& source = {}, bool xyz_only = false);

// Appends the chunk holding `records` (a whole number of record_length records, at
// least one) to `out`.
void encode_chunk(const LaszipInfo& info, std::span<const std::uint8_t> records, std::size_t record_length,
                  std::vector<std::uint8_t>& out);

}  // namespace vola::io::laz
