// translate_las: LAS/LAZ point records into a LAS or LAZ file, record for record. The
// header block is the input's own bytes with the fields that describe the layout
// rewritten (point format's compression bit, VLR count, offset to the points, EVLR start);
// VLRs and EVLRs are copied but those of the input's compression (laszip, COPC), and a
// LAZ output gets its own laszip VLR and chunk table.
#include <algorithm>
#include <cstring>
#include <fstream>

#include "las_format.hpp"
#include "vola/output_file.hpp"
#include "vola/error.hpp"
#include "vola/io/las.hpp"

namespace vola::io {

namespace {

constexpr std::size_t kLazChunkPoints = 50000;  // LASzip's default chunk

bool is_compression_record(const LasVlr& v) { return v.user_id == "laszip encoded" || v.user_id == "copc"; }

template <class T>
void store(std::vector<std::uint8_t>& bytes, std::size_t at, T value) {
  std::memcpy(bytes.data() + at, &value, sizeof value);  // LAS is little-endian, as every target vola builds for
}

std::vector<std::uint8_t> read_bytes(std::ifstream& in, const std::string& path, std::uint64_t offset, std::uint64_t n) {
  std::vector<std::uint8_t> bytes(static_cast<std::size_t>(n));
  in.clear();
  in.seekg(static_cast<std::streamoff>(offset));
  in.read(reinterpret_cast<char*>(bytes.data()), static_cast<std::streamsize>(n));
  if (static_cast<std::uint64_t>(in.gcount()) != n) throw FormatError(path, offset, "cannot read " + std::to_string(n) + " bytes");
  return bytes;
}

// One VLR (54-byte header and data) as a LAS file holds it.
void append_vlr(std::vector<std::uint8_t>& out, const std::string& user, std::uint16_t record,
                const std::string& description, const std::vector<std::uint8_t>& data) {
  std::uint8_t head[54] = {};
  std::memcpy(head + 2, user.data(), std::min<std::size_t>(user.size(), 16));
  std::memcpy(head + 18, &record, 2);
  const auto length = static_cast<std::uint16_t>(data.size());
  std::memcpy(head + 20, &length, 2);
  std::memcpy(head + 22, description.data(), std::min<std::size_t>(description.size(), 32));
  out.insert(out.end(), head, head + 54);
  out.insert(out.end(), data.begin(), data.end());
}

// The records, compressed into chunks of kLazChunkPoints after an 8-byte placeholder for
// the chunk table's offset, then the chunk table; returns the bytes written.
std::uint64_t write_laz_points(LasReader& reader, const laz::LaszipInfo& info, OutputFile& out, std::uint64_t points_at,
                               const std::function<void(std::uint64_t, std::uint64_t)>& progress) {
  const LasHeader& hd = reader.header();
  const std::int64_t placeholder = -1;
  out.write(&placeholder, 8);
  std::vector<laz::ChunkEntry> chunks;
  std::vector<std::uint8_t> records, compressed;
  std::uint64_t at = points_at + 8;
  for (;;) {
    records.clear();
    while (records.size() < kLazChunkPoints * hd.record_length) {
      const auto r = reader.read_records(kLazChunkPoints - records.size() / hd.record_length);
      if (r.empty()) break;
      records.insert(records.end(), r.begin(), r.end());
    }
    if (records.empty()) break;
    compressed.clear();
    laz::encode_chunk(info, records, hd.record_length, compressed);
    out.write(compressed.data(), compressed.size());
    chunks.push_back({records.size() / hd.record_length, at, compressed.size()});
    at += compressed.size();
    if (progress) progress(reader.points_read(), hd.point_count);
  }
  const std::vector<std::uint8_t> table = laz::chunk_table_bytes(info, chunks);
  out.write(table.data(), table.size());
  const auto table_at = static_cast<std::int64_t>(at);
  if (std::fseek(out.stream(), static_cast<long>(points_at), SEEK_SET) != 0 ||
      std::fwrite(&table_at, 8, 1, out.stream()) != 1 || std::fseek(out.stream(), 0, SEEK_END) != 0)
    throw IoError(out.path() + ": cannot write the LAZ chunk table's offset");
  return at + table.size() - points_at;
}

std::uint64_t write_las_points(LasReader& reader, OutputFile& out,
                               const std::function<void(std::uint64_t, std::uint64_t)>& progress) {
  const LasHeader& hd = reader.header();
  const std::size_t batch = std::max<std::size_t>(1, kLasRecordBatchBytes / hd.record_length);
  std::uint64_t bytes = 0;
  for (;;) {
    const auto r = reader.read_records(batch);
    if (r.empty()) break;
    out.write(r.data(), r.size());
    bytes += r.size();
    if (progress) progress(reader.points_read(), hd.point_count);
  }
  return bytes;
}

}  // namespace

void translate_las(const std::string& input, const std::string& output,
                   const std::function<void(std::uint64_t, std::uint64_t)>& progress) {
  LasReader reader(input);
  const LasHeader& hd = reader.header();
  const bool laz_out = las::laz_path(output);
  std::ifstream in(input, std::ios::binary);
  if (!in) throw IoError(input + ": cannot open");

  std::vector<std::uint8_t> head = read_bytes(in, input, 0, hd.header_size);
  std::vector<std::uint8_t> vlrs;
  std::uint32_t vlr_count = 0;
  for (const LasVlr& v : hd.vlrs) {
    if (v.extended || is_compression_record(v)) continue;
    append_vlr(vlrs, v.user_id, v.record_id, v.description, v.data);
    ++vlr_count;
  }
  laz::LaszipInfo info;
  if (laz_out) {
    info = laz::laszip_info_for(hd.point_format, hd.record_length);
    append_vlr(vlrs, "laszip encoded", 22204, "vola LAZ", laz::laszip_vlr_payload(info));
    ++vlr_count;
  }
  const std::uint64_t points_at = head.size() + vlrs.size();
  if (points_at > 0xFFFFFFFFu) throw FormatError(input, 96, "the VLRs do not fit a LAS header's 32-bit offset");
  head[104] = static_cast<std::uint8_t>(hd.point_format | (laz_out ? 0x80 : 0));
  store(head, 96, static_cast<std::uint32_t>(points_at));
  store(head, 100, vlr_count);

  OutputFile out(output);
  out.write(head.data(), head.size());
  out.write(vlrs.data(), vlrs.size());
  const std::uint64_t point_bytes =
      laz_out ? write_laz_points(reader, info, out, points_at, progress) : write_las_points(reader, out, progress);
  if (reader.points_read() != hd.point_count)
    throw FormatError(input, hd.offset_to_points, "holds " + std::to_string(reader.points_read()) + " points, not the " +
                                                      std::to_string(hd.point_count) + " its header says");
  // EVLRs (LAS 1.4): copied raw, 60-byte header and data, after the points.
  std::uint32_t evlr_count = 0;
  for (const LasVlr& v : hd.vlrs) {
    if (!v.extended || is_compression_record(v)) continue;
    const auto bytes = read_bytes(in, input, v.offset - 60, 60 + v.length);
    out.write(bytes.data(), bytes.size());
    ++evlr_count;
  }
  if (hd.version_minor >= 4) {
    std::vector<std::uint8_t> evlr_fields(12);
    store(evlr_fields, 0, static_cast<std::uint64_t>(evlr_count ? points_at + point_bytes : 0));
    store(evlr_fields, 8, evlr_count);
    if (std::fseek(out.stream(), 235, SEEK_SET) != 0 || std::fwrite(evlr_fields.data(), 12, 1, out.stream()) != 1 ||
        std::fseek(out.stream(), 0, SEEK_END) != 0)
      throw IoError(output + ": cannot write the EVLR fields of the header");
  }
  out.commit();
}

}  // namespace vola::io
