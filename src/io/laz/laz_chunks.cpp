// The chunk table, and decode_chunk / encode_chunk: the checks around the chunk coders.
#include <algorithm>
#include <cstring>
#include <string>

#include "integer_coder.hpp"
#include "record_layout.hpp"
#include "vola/error.hpp"
#include "vola/little_endian.hpp"

namespace vola::io::laz {
namespace {

[[noreturn]] void fail(const std::string& source, std::uint64_t offset, const std::string& cause) {
  VOLA_THROW(FormatError(source, offset, "LAZ " + cause));
}

std::uint64_t read_u64(const ReadAt& read_at, std::uint64_t offset) {
  std::uint8_t raw[8];
  read_at(offset, 8, raw);
  return load_le<std::uint64_t>(raw);
}

// Where the table is: the first 8 bytes of point data, or (-1 there) the file's last 8,
// written by a writer that could not seek back.
std::uint64_t table_offset(const ReadAt& read_at, std::uint64_t file_size, std::uint64_t offset_to_points,
                           const std::string& source) {
  if (offset_to_points > file_size || file_size - offset_to_points < 8)
    fail(source, offset_to_points, "point data has no room for the chunk table offset");
  std::uint64_t at = read_u64(read_at, offset_to_points);
  if (at == ~std::uint64_t{0}) at = read_u64(read_at, file_size - 8);
  if (at == offset_to_points)
    fail(source, offset_to_points, "chunk table is missing (the writer did not finish the file)");
  if (at < offset_to_points + 8 || at > file_size || file_size - at < 8)
    fail(source, offset_to_points,
         "chunk table offset " + std::to_string(at) + " is outside the file (" + std::to_string(file_size) + " bytes)");
  return at;
}

struct CodedTable {
  std::vector<std::uint32_t> counts, sizes;
};

CodedTable decode_table(const LaszipInfo& info, std::span<const std::uint8_t> coded, std::uint32_t chunks,
                        std::uint64_t table_at, const std::string& source) {
  const bool variable = info.chunk_size == kVariableChunkSize;
  CodedTable table;
  table.sizes.resize(chunks);
  if (variable) table.counts.resize(chunks);
  ArithmeticDecoder d(coded);
  IntegerCoder ic(32, 2, true);
  // Each entry is predicted by the one before (not the running sum).
  for (std::uint32_t i = 0; i < chunks; ++i) {
    if (variable) table.counts[i] = static_cast<std::uint32_t>(ic.decode(d, i ? static_cast<std::int32_t>(table.counts[i - 1]) : 0, 0));
    table.sizes[i] = static_cast<std::uint32_t>(ic.decode(d, i ? static_cast<std::int32_t>(table.sizes[i - 1]) : 0, 1));
  }
  if (d.overrun()) fail(source, table_at + 8 + coded.size(), "chunk table is cut short");
  return table;
}

}  // namespace

std::vector<ChunkEntry> read_chunk_table(const LaszipInfo& info, const ReadAt& read_at, std::uint64_t file_size,
                                         std::uint64_t offset_to_points, std::uint64_t point_count,
                                         const std::string& source) {
  if (info.compressor == 1) {  // one stream of every point, no table
    if (offset_to_points > file_size) fail(source, offset_to_points, "point data starts past the end of the file");
    if (point_count == 0) return {};
    return {{point_count, offset_to_points, file_size - offset_to_points}};
  }
  if (point_count == 0 && (offset_to_points >= file_size || file_size - offset_to_points < 8)) return {};
  const std::uint64_t table_at = table_offset(read_at, file_size, offset_to_points, source);
  std::uint8_t head[8];
  read_at(table_at, 8, head);
  const auto version = load_le<std::uint32_t>(head);
  const auto chunks = load_le<std::uint32_t>(head + 4);
  if (version != 0) fail(source, table_at, "chunk table version " + std::to_string(version) + " (expected 0)");
  // Every chunk holds at least one point and one byte before the table.
  if (chunks > point_count || chunks > table_at - offset_to_points - 8)
    fail(source, table_at + 4,
         "chunk table lists " + std::to_string(chunks) + " chunks for " + std::to_string(point_count) + " points in " +
             std::to_string(table_at - offset_to_points - 8) + " bytes");
  if (chunks == 0) {
    if (point_count) fail(source, table_at + 4, "chunk table lists no chunks for " + std::to_string(point_count) + " points");
    return {};
  }
  // A chunk size of 0 (lasR's COPC writer puts it in the laszip record) is one chunk that
  // never ends, as LASzip and laz-perf read it: the first chunk holds every point, from
  // the table's offset to the table, whatever the table's entries say (that writer's
  // hold a count and a size, as variable chunks' do, which a table of fixed chunks does
  // not). A table of more chunks cannot be read that way.
  if (info.chunk_size == 0) {
    if (chunks > 1)
      fail(source, table_at + 4,
           "chunk table lists " + std::to_string(chunks) +
               " chunks, but the laszip record's chunk size of 0 puts "
               "every point in the first");
    return {{point_count, offset_to_points + 8, table_at - offset_to_points - 8}};
  }
  // An entry takes at most ~14 coded bytes; read no more than the table can use.
  const std::uint64_t available = file_size - table_at - 8;
  std::vector<std::uint8_t> coded(static_cast<std::size_t>(std::min<std::uint64_t>(available, 16ull * chunks + 16)));
  if (!coded.empty()) read_at(table_at + 8, coded.size(), coded.data());
  const CodedTable table = decode_table(info, coded, chunks, table_at, source);

  std::vector<ChunkEntry> entries(chunks);
  std::uint64_t offset = offset_to_points + 8, remaining = point_count;
  for (std::uint32_t i = 0; i < chunks; ++i) {
    const std::string name = "chunk " + std::to_string(i);
    const std::uint64_t size = table.sizes[i];
    if (size == 0 || size > table_at - offset)
      fail(source, table_at, name + " of " + std::to_string(size) + " bytes at " + std::to_string(offset) +
                                 " does not fit before the chunk table at " + std::to_string(table_at));
    const std::uint64_t count = table.counts.empty() ? std::min<std::uint64_t>(info.chunk_size, remaining) : table.counts[i];
    if (count > remaining || (count == 0 && table.counts.empty()))
      fail(source, table_at, name + " holds points beyond the header's " + std::to_string(point_count));
    entries[i] = {count, offset, size};
    offset += size;
    remaining -= count;
  }
  if (remaining)
    fail(source, table_at, "the chunks hold " + std::to_string(point_count - remaining) + " of the header's " +
                               std::to_string(point_count) + " points");
  return entries;
}

std::vector<std::uint8_t> chunk_table_bytes(const LaszipInfo& info, std::span<const ChunkEntry> chunks) {
  std::vector<std::uint8_t> out(8, 0);
  const auto count = static_cast<std::uint32_t>(chunks.size());
  std::memcpy(out.data() + 4, &count, 4);
  if (chunks.empty()) return out;
  ArithmeticEncoder e;
  IntegerCoder ic(32, 2, false);
  const bool variable = info.chunk_size == kVariableChunkSize;
  for (std::size_t i = 0; i < chunks.size(); ++i) {
    if (variable)
      ic.encode(e, i ? static_cast<std::int32_t>(chunks[i - 1].point_count) : 0, static_cast<std::int32_t>(chunks[i].point_count), 0);
    ic.encode(e, i ? static_cast<std::int32_t>(chunks[i - 1].byte_size) : 0, static_cast<std::int32_t>(chunks[i].byte_size), 1);
  }
  e.finish();
  out.insert(out.end(), e.bytes().begin(), e.bytes().end());
  return out;
}

void decode_chunk(const LaszipInfo& info, std::span<const std::uint8_t> chunk, std::uint64_t count,
                  std::uint8_t* records, std::size_t record_length, std::uint64_t chunk_index,
                  std::uint64_t chunk_offset, const std::string& source, bool xyz_only) {
  const RecordLayout layout = record_layout(info, source, 0);
  const std::string name = "chunk " + std::to_string(chunk_index);
  if (record_length != layout.length)
    fail(source, chunk_offset, name + ": records of " + std::to_string(record_length) + " bytes, but the laszip items make " +
                                   std::to_string(layout.length));
  if (info.compressor == 2 && info.chunk_size != kVariableChunkSize && info.chunk_size != 0 && count > info.chunk_size)
    fail(source, chunk_offset, name + ": " + std::to_string(count) + " points in chunks of " + std::to_string(info.chunk_size));
  const std::uint64_t overrun =
      layout.layered ? decode_layered_chunk(layout, chunk, count, records, name, chunk_offset, source, xyz_only)
                     : decode_pointwise_chunk(layout, chunk, count, records);
  if (overrun)
    fail(source, chunk_offset + chunk.size(),
         name + " (" + std::to_string(chunk.size()) + " bytes at " + std::to_string(chunk_offset) +
             ") ends before its " + std::to_string(count) + " points do (truncated or corrupt)");
}

void encode_chunk(const LaszipInfo& info, std::span<const std::uint8_t> records, std::size_t record_length,
                  std::vector<std::uint8_t>& out) {
  const RecordLayout layout = record_layout(info, {}, 0);
  if (record_length != layout.length || records.empty() || records.size() % record_length != 0)
    VOLA_THROW(InvalidArgument("LAZ: encode_chunk needs whole records of the items' " + std::to_string(layout.length) +
                               " bytes"));
  if (layout.layered) encode_layered_chunk(layout, records, out);
  else encode_pointwise_chunk(layout, records, out);
}

}  // namespace vola::io::laz
