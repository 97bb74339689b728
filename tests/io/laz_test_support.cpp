#include "laz_test_support.hpp"

#include <algorithm>
#include <cstring>
#include <fstream>
#include <iterator>
#include <stdexcept>

namespace vola_laz_test {
namespace {

template <class T>
T get(const Bytes& b, std::size_t at) {
  if (at + sizeof(T) > b.size()) throw std::runtime_error("short LAS header");
  T v;
  std::memcpy(&v, b.data() + at, sizeof v);
  return v;
}

}  // namespace

LasFile read_las_file(const vola_io_test::fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return parse_las_file(Bytes(std::istreambuf_iterator<char>(in), {}), path.filename().string());
}

LasFile parse_las_file(Bytes bytes, std::string name) {
  LasFile f;
  f.name = std::move(name);
  f.bytes = std::move(bytes);
  const Bytes& b = f.bytes;
  const auto header_size = get<std::uint16_t>(b, 94);
  f.offset_to_points = get<std::uint32_t>(b, 96);
  const auto vlrs = get<std::uint32_t>(b, 100);
  f.point_format = get<std::uint8_t>(b, 104) & 0x3F;
  f.record_length = get<std::uint16_t>(b, 105);
  f.point_count = get<std::uint32_t>(b, 107);
  if (b[25] >= 4 && header_size >= 255 && f.point_count == 0) f.point_count = get<std::uint64_t>(b, 247);
  std::size_t at = header_size;
  for (std::uint32_t i = 0; i < vlrs; ++i) {
    const std::string user(reinterpret_cast<const char*>(b.data() + at + 2), strnlen(reinterpret_cast<const char*>(b.data() + at + 2), 16));
    const auto record = get<std::uint16_t>(b, at + 18);
    const auto length = get<std::uint16_t>(b, at + 20);
    if (user == "laszip encoded" && record == 22204) {
      f.laszip_offset = at + 54;
      f.laszip.assign(b.begin() + static_cast<std::ptrdiff_t>(at + 54), b.begin() + static_cast<std::ptrdiff_t>(at + 54 + length));
    }
    at += 54 + std::size_t{length};
  }
  return f;
}

Bytes decode_all(const LasFile& file, bool coordinates_only) {
  namespace laz = vola::io::laz;
  const laz::LaszipInfo info = laz::parse_laszip_vlr(file.laszip, file.name, file.laszip_offset);
  const auto read_at = [&file](std::uint64_t offset, std::uint64_t n, std::uint8_t* out) {
    if (offset > file.bytes.size() || n > file.bytes.size() - offset) throw std::runtime_error("read past the end");
    std::memcpy(out, file.bytes.data() + offset, n);
  };
  const auto chunks = laz::read_chunk_table(info, read_at, file.bytes.size(), file.offset_to_points, file.point_count, file.name);
  Bytes records(file.point_count * file.record_length);
  std::uint64_t done = 0;
  for (std::size_t i = 0; i < chunks.size(); ++i) {
    const laz::ChunkEntry& c = chunks[i];
    laz::decode_chunk(info, std::span(file.bytes).subspan(c.byte_offset, c.byte_size), c.point_count,
                      records.data() + done * file.record_length, file.record_length, i, c.byte_offset, file.name,
                      coordinates_only);
    done += c.point_count;
  }
  return records;
}

Bytes las_records(const LasFile& file) {
  const std::size_t n = file.point_count * file.record_length;
  if (file.offset_to_points + n > file.bytes.size()) throw std::runtime_error(file.name + ": short point data");
  return Bytes(file.bytes.begin() + file.offset_to_points, file.bytes.begin() + static_cast<std::ptrdiff_t>(file.offset_to_points + n));
}

LasFile make_laz(vola::io::laz::LaszipInfo info, std::span<const std::uint8_t> records, std::uint64_t chunk_points) {
  namespace laz = vola::io::laz;
  if (info.compressor != 1 && info.chunk_size != laz::kVariableChunkSize)
    info.chunk_size = static_cast<std::uint32_t>(chunk_points);
  LasFile f;
  f.name = "made.laz";
  f.record_length = static_cast<std::uint16_t>(info.record_length());
  f.point_count = records.size() / f.record_length;
  f.laszip = laz::laszip_vlr_payload(info);
  f.laszip_offset = 227;
  f.bytes.assign(227, 0);
  f.bytes.insert(f.bytes.end(), f.laszip.begin(), f.laszip.end());
  f.offset_to_points = static_cast<std::uint32_t>(f.bytes.size());
  if (info.compressor == 1) {  // one stream, no chunk table
    if (f.point_count) laz::encode_chunk(info, records, f.record_length, f.bytes);
    return f;
  }
  f.bytes.resize(f.bytes.size() + 8);
  std::vector<laz::ChunkEntry> chunks;
  for (std::uint64_t first = 0; first < f.point_count; first += chunk_points) {
    const std::uint64_t count = std::min(chunk_points, f.point_count - first);
    const std::size_t offset = f.bytes.size();
    laz::encode_chunk(info, records.subspan(first * f.record_length, count * f.record_length), f.record_length, f.bytes);
    chunks.push_back({count, offset, f.bytes.size() - offset});
  }
  const std::uint64_t table_at = f.bytes.size();
  std::memcpy(f.bytes.data() + f.offset_to_points, &table_at, 8);
  const Bytes table = laz::chunk_table_bytes(info, chunks);
  f.bytes.insert(f.bytes.end(), table.begin(), table.end());
  return f;
}

Bytes las_file_bytes(std::uint8_t point_format, std::uint16_t record_length, std::span<const std::uint8_t> records) {
  const bool v14 = point_format >= 6;
  const std::uint16_t header = v14 ? 375 : 227;
  const std::uint64_t count = records.size() / record_length;
  Bytes f(header, 0);
  auto put = [&f](std::size_t at, auto value) { std::memcpy(f.data() + at, &value, sizeof value); };
  std::memcpy(f.data(), "LASF", 4);
  f[24] = 1;
  f[25] = v14 ? 4 : 2;
  put(94, header);
  put(96, std::uint32_t{header});
  f[104] = point_format;
  put(105, record_length);
  put(107, static_cast<std::uint32_t>(v14 ? 0 : count));
  for (int axis = 0; axis < 3; ++axis) put(131 + 8 * axis, 0.01);
  if (v14) put(247, count);
  f.insert(f.end(), records.begin(), records.end());
  return f;
}

Bytes laz_from_las(const LasFile& las, std::uint32_t chunk_points) {
  return laz_from_las(las, chunk_points, vola::io::laz::laszip_info_for(las.point_format, las.record_length));
}

Bytes laz_from_las(const LasFile& las, std::uint32_t chunk_points, vola::io::laz::LaszipInfo info) {
  namespace laz = vola::io::laz;
  const Bytes records = las_records(las);
  const LasFile made = make_laz(info, records, chunk_points);  // the chunks and table
  if (info.compressor != 1) info.chunk_size = chunk_points;
  const Bytes payload = laz::laszip_vlr_payload(info);
  // The header and VLRs, without any padding before the point data.
  std::size_t vlrs_end = get<std::uint16_t>(las.bytes, 94);
  for (std::uint32_t i = 0, n = get<std::uint32_t>(las.bytes, 100); i < n; ++i)
    vlrs_end += 54 + std::size_t{get<std::uint16_t>(las.bytes, vlrs_end + 20)};
  Bytes out(las.bytes.begin(), las.bytes.begin() + static_cast<std::ptrdiff_t>(vlrs_end));
  Bytes vlr(54, 0);
  std::memcpy(vlr.data() + 2, "laszip encoded", 14);
  const std::uint16_t record = 22204, length = static_cast<std::uint16_t>(payload.size());
  std::memcpy(vlr.data() + 18, &record, 2);
  std::memcpy(vlr.data() + 20, &length, 2);
  std::memcpy(vlr.data() + 22, "vola LAZ codec", 14);
  out.insert(out.end(), vlr.begin(), vlr.end());
  out.insert(out.end(), payload.begin(), payload.end());
  const auto offset_to_points = static_cast<std::uint32_t>(out.size());
  std::uint32_t vlrs;
  std::memcpy(&vlrs, out.data() + 100, 4);
  ++vlrs;
  std::memcpy(out.data() + 100, &vlrs, 4);
  std::memcpy(out.data() + 96, &offset_to_points, 4);
  out[104] = static_cast<std::uint8_t>(las.point_format | 0x80);
  if (out[25] >= 4 && out.size() >= 247) std::memset(out.data() + 235, 0, 12);  // no EVLRs
  if (info.compressor == 1) {  // one stream, no table
    out.insert(out.end(), made.bytes.begin() + made.offset_to_points, made.bytes.end());
    return out;
  }
  // The chunks and table, with the offsets moved to this file's point data.
  const std::int64_t shift = static_cast<std::int64_t>(offset_to_points) - made.offset_to_points;
  std::uint64_t table_at;
  std::memcpy(&table_at, made.bytes.data() + made.offset_to_points, 8);
  table_at = static_cast<std::uint64_t>(static_cast<std::int64_t>(table_at) + shift);
  out.resize(out.size() + 8);
  std::memcpy(out.data() + offset_to_points, &table_at, 8);
  out.insert(out.end(), made.bytes.begin() + made.offset_to_points + 8, made.bytes.end());
  return out;
}

}  // namespace vola_laz_test
