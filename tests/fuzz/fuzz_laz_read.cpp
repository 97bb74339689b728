// Fuzz entry point of the LAZ codec: the input is a whole LAZ file. The LAS header and
// VLRs are walked here (only the fields the codec needs); the laszip record, chunk table
// and chunks go through vola::io::laz. Only vola::Error may escape; records that decode
// must survive encode -> decode unchanged.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <span>
#include <vector>

#include "fuzz_seeds.hpp"
#include "vola/error.hpp"
#include "vola/io/laz.hpp"

namespace {

namespace laz = vola::io::laz;

// Bounds of this harness (not of the codec): keep each input fast and small in memory.
constexpr std::uint64_t kMaxRecordBytes = std::uint64_t{32} << 20;
constexpr std::uint16_t kMaxRecordLength = 512;

using vola_fuzz::check;

template <class T>
bool get(std::span<const std::uint8_t> b, std::size_t at, T& v) {
  if (at > b.size() || b.size() - at < sizeof v) return false;
  std::memcpy(&v, b.data() + at, sizeof v);
  return true;
}

void round_trip(const laz::LaszipInfo& info, std::span<const std::uint8_t> records, std::size_t record_length) {
  std::vector<std::uint8_t> chunk;
  laz::encode_chunk(info, records, record_length, chunk);
  std::vector<std::uint8_t> back(records.size());
  laz::decode_chunk(info, chunk, records.size() / record_length, back.data(), record_length);
  check(std::memcmp(back.data(), records.data(), records.size()) == 0);
}

void read_laz(std::span<const std::uint8_t> file) {
  std::uint16_t header_size = 0, record_length = 0;
  std::uint32_t offset_to_points = 0, vlrs = 0, legacy_count = 0;
  if (!get(file, 94, header_size) || !get(file, 96, offset_to_points) || !get(file, 100, vlrs) ||
      !get(file, 105, record_length) || !get(file, 107, legacy_count))
    return;
  std::uint64_t count = legacy_count;
  if (count == 0) get(file, 247, count);
  laz::LaszipInfo info;
  bool found = false;
  std::size_t at = header_size;
  for (std::uint32_t i = 0; i < vlrs && i < 64 && !found; ++i) {
    std::uint16_t record = 0, length = 0;
    if (!get(file, at + 18, record) || !get(file, at + 20, length) || file.size() - at < 54 + std::size_t{length}) return;
    if (record == 22204) {
      info = laz::parse_laszip_vlr(file.subspan(at + 54, length), "fuzz", at + 54);
      found = true;
    }
    at += 54 + std::size_t{length};
  }
  if (!found || record_length == 0 || record_length > kMaxRecordLength) return;
  if (count * record_length > kMaxRecordBytes || count > kMaxRecordBytes) return;
  const auto read_at = [file](std::uint64_t offset, std::uint64_t n, std::uint8_t* out) {
    check(offset <= file.size() && n <= file.size() - offset);  // the codec checks before it reads
    std::memcpy(out, file.data() + offset, n);
  };
  const auto chunks = laz::read_chunk_table(info, read_at, file.size(), offset_to_points, count, "fuzz");
  std::uint64_t total = 0;
  for (const auto& c : chunks) {
    check(c.byte_offset >= offset_to_points && c.byte_offset <= file.size() && c.byte_size <= file.size() - c.byte_offset);
    total += c.point_count;
  }
  check(total == count);
  std::vector<std::uint8_t> records, coordinates;
  for (std::size_t i = 0; i < chunks.size(); ++i) {
    const auto& c = chunks[i];
    // Coordinates alone first (a pass of the occupancy conversion), then whole records:
    // a chunk whose coordinates decode may still fail whole (more layers), never the
    // other way round, and the coordinates must be the whole decode's.
    coordinates.assign(c.point_count * record_length, 0);
    bool coordinates_decoded = true;
    try {
      laz::decode_chunk(info, file.subspan(c.byte_offset, c.byte_size), c.point_count, coordinates.data(), record_length,
                        i, c.byte_offset, "fuzz", true);
    } catch (const vola::Error&) {
      coordinates_decoded = false;
    }
    records.assign(c.point_count * record_length, 0);
    laz::decode_chunk(info, file.subspan(c.byte_offset, c.byte_size), c.point_count, records.data(), record_length, i,
                      c.byte_offset, "fuzz");
    check(coordinates_decoded);
    for (std::size_t r = 0; r < c.point_count; ++r)
      check(std::memcmp(coordinates.data() + r * record_length, records.data() + r * record_length, 12) == 0);
    if (!records.empty() && records.size() <= 64 * 1024) round_trip(info, records, record_length);
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    read_laz({data, size});
    ++vola_fuzz::stats().parsed;
  } catch (const vola::Error&) {
    ++vola_fuzz::stats().refused;
  }
  return 0;
}
