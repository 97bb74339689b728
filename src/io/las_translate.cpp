// translate_las: LAS/LAZ point records into a LAS or LAZ file, record for record. The
// header block is the input's own bytes with the fields that describe the layout
// rewritten (point format's compression bit, VLR count, offset to the points, EVLR start);
// VLRs and EVLRs are copied but those of the input's compression (laszip, COPC), and a
// LAZ output gets its own laszip VLR and chunk table.
#include <algorithm>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <optional>
#include <span>

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

// Bytes [offset, offset + n) of the input onto the output, in pieces of 8 MiB: waveform
// records after the points run to gigabytes.
void copy_bytes(std::ifstream& in, const std::string& path, std::uint64_t offset, std::uint64_t n, OutputFile& out) {
  constexpr std::uint64_t kPiece = std::uint64_t{8} << 20;
  for (std::uint64_t done = 0; done < n;) {
    const std::uint64_t size = std::min(kPiece, n - done);
    const auto piece = read_bytes(in, path, offset + done, size);
    out.write(piece.data(), piece.size());
    done += size;
  }
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

// The records to write, in order: every record of the reader, or with edits only the
// kept ones, their classification set from the edited column.
class RecordSource {
 public:
  RecordSource(LasReader& reader, const std::optional<LasRecordEdits>& edits) : reader_(reader), edits_(edits) {
    if (edits_) {
      const auto column = std::find_if(edits_->points.attributes.begin(), edits_->points.attributes.end(),
                                       [](const PointAttribute& a) { return a.name == "classification"; });
      if (column != edits_->points.attributes.end()) classes_ = &column->values;
    }
  }
  // Up to max_points records (fewer at the end; empty when there are no more).
  std::span<const std::uint8_t> next(std::size_t max_points) {
    if (!edits_) return reader_.read_records(max_points);
    const std::size_t length = reader_.header().record_length;
    buffer_.clear();
    while (buffer_.empty()) {
      const std::uint64_t first = reader_.points_read();
      const auto records = reader_.read_records(max_points);
      if (records.empty()) break;
      for (std::size_t j = 0; j < records.size() / length; ++j) {
        if (kept_at_ >= edits_->kept.size() || edits_->kept[kept_at_] != first + j) continue;
        const std::size_t at = buffer_.size();
        buffer_.insert(buffer_.end(), records.begin() + static_cast<std::ptrdiff_t>(j * length),
                       records.begin() + static_cast<std::ptrdiff_t>((j + 1) * length));
        if (classes_) set_class(buffer_.data() + at, (*classes_)[kept_at_]);
        ++kept_at_;
      }
    }
    return buffer_;
  }

 private:
  void set_class(std::uint8_t* record, double value) const {
    const auto c = static_cast<unsigned>(value);
    if (reader_.header().extended_format()) {
      record[16] = static_cast<std::uint8_t>(c);
    } else {
      if (c > 31)
        throw InvalidArgument("classification " + std::to_string(c) + " does not fit point format " +
                              std::to_string(reader_.header().point_format) + " (0..31)");
      record[15] = static_cast<std::uint8_t>((record[15] & 0xE0u) | c);
    }
  }
  LasReader& reader_;
  const std::optional<LasRecordEdits>& edits_;
  const std::vector<double>* classes_ = nullptr;
  std::size_t kept_at_ = 0;
  std::vector<std::uint8_t> buffer_;
};

// The header fields that describe the points, for the points left after edits: counts,
// counts by return, bounds.
void rewrite_point_fields(std::vector<std::uint8_t>& head, const LasHeader& hd, const PointCloud& points) {
  const std::size_t n = points.size();
  const Box box = points.bounds();
  const auto returns = std::find_if(points.attributes.begin(), points.attributes.end(),
                                    [](const PointAttribute& a) { return a.name == "return_number"; });
  std::uint64_t by_return[15] = {};
  if (returns != points.attributes.end())
    for (const double r : returns->values)
      if (r >= 1 && r <= 15) ++by_return[static_cast<int>(r) - 1];
  const bool legacy_counts_fit = n <= 0xFFFFFFFFu && hd.point_format < 6;
  store(head, 107, static_cast<std::uint32_t>(legacy_counts_fit ? n : 0));
  for (int r = 0; r < 5; ++r)
    store(head, 111 + 4 * static_cast<std::size_t>(r),
          static_cast<std::uint32_t>(legacy_counts_fit ? by_return[r] : 0));
  const double bounds[6] = {box.max[0], box.min[0], box.max[1], box.min[1], box.max[2], box.min[2]};
  for (int k = 0; k < 6; ++k) store(head, 179 + 8 * static_cast<std::size_t>(k), n ? bounds[k] : 0.0);
  if (hd.version_minor >= 4 && head.size() >= 375) {
    store(head, 247, static_cast<std::uint64_t>(n));
    for (int r = 0; r < 15; ++r) store(head, 255 + 8 * static_cast<std::size_t>(r), by_return[r]);
  }
}

// The records, compressed into chunks of kLazChunkPoints after an 8-byte placeholder for
// the chunk table's offset, then the chunk table; returns the bytes written.
std::uint64_t write_laz_points(LasReader& reader, RecordSource& source, const laz::LaszipInfo& info, OutputFile& out, std::uint64_t points_at,
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
      const auto r = source.next(kLazChunkPoints - records.size() / hd.record_length);
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

std::uint64_t write_las_points(LasReader& reader, RecordSource& source, OutputFile& out,
                               const std::function<void(std::uint64_t, std::uint64_t)>& progress) {
  const LasHeader& hd = reader.header();
  const std::size_t batch = std::max<std::size_t>(1, kLasRecordBatchBytes / hd.record_length);
  std::uint64_t bytes = 0;
  for (;;) {
    const auto r = source.next(batch);
    if (r.empty()) break;
    out.write(r.data(), r.size());
    bytes += r.size();
    if (progress) progress(reader.points_read(), hd.point_count);
  }
  return bytes;
}

}  // namespace

void translate_las(const std::string& input, const std::string& output,
                   const std::function<void(std::uint64_t, std::uint64_t)>& progress,
                   const std::optional<LasRecordEdits>& edits) {
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
    // As the file holds it, reserved field (LAS 1.0's 0xAABB) and all.
    const auto bytes = read_bytes(in, input, v.offset - 54, 54 + v.length);
    vlrs.insert(vlrs.end(), bytes.begin(), bytes.end());
    ++vlr_count;
  }
  // Bytes between the last VLR and the points (LAS 1.0's 0xDDCC signature, or user
  // data a writer put there) stay between the VLRs and the points.
  std::uint64_t vlrs_end = hd.header_size;
  for (const LasVlr& v : hd.vlrs)
    if (!v.extended) vlrs_end = std::max(vlrs_end, v.offset + v.length);
  const std::vector<std::uint8_t> user_bytes =
      hd.offset_to_points > vlrs_end ? read_bytes(in, input, vlrs_end, hd.offset_to_points - vlrs_end)
                                     : std::vector<std::uint8_t>{};
  laz::LaszipInfo info;
  if (laz_out) {
    info = laz::laszip_info_for(hd.point_format, hd.record_length);
    append_vlr(vlrs, "laszip encoded", 22204, "vola LAZ", laz::laszip_vlr_payload(info));
    ++vlr_count;
  }
  const std::uint64_t points_at = head.size() + vlrs.size() + user_bytes.size();
  if (points_at > 0xFFFFFFFFu) throw FormatError(input, 96, "the VLRs do not fit a LAS header's 32-bit offset");
  head[104] = static_cast<std::uint8_t>(hd.point_format | (laz_out ? 0x80 : 0));
  store(head, 96, static_cast<std::uint32_t>(points_at));
  store(head, 100, vlr_count);
  if (edits) {
    rewrite_point_fields(head, hd, edits->points);
  } else if (hd.version_minor >= 4 && head.size() >= 255) {
    // The count the records were read by, in the 64-bit field too: a LAS 1.4 file of
    // format 0-5 with only its legacy count set (against the specification) read as that
    // many points, but its copy said 0 to readers that take the 64-bit field.
    std::uint64_t stated = 0;
    std::memcpy(&stated, head.data() + 247, 8);
    if (stated == 0) store(head, 247, static_cast<std::uint64_t>(hd.point_count));
  }

  OutputFile out(output);
  out.write(head.data(), head.size());
  out.write(vlrs.data(), vlrs.size());
  out.write(user_bytes.data(), user_bytes.size());
  RecordSource source(reader, edits);
  const std::uint64_t point_bytes = laz_out ? write_laz_points(reader, source, info, out, points_at, progress)
                                            : write_las_points(reader, source, out, progress);
  if (reader.points_read() != hd.point_count)
    throw FormatError(input, hd.offset_to_points, "holds " + std::to_string(reader.points_read()) + " points, not the " +
                                                      std::to_string(hd.point_count) + " its header says");
  // Internal waveforms (global encoding bit 1): the header's field at 227 says where the
  // waveform data packets' record starts (the points' wave packets point into it). LAS
  // 1.3 has it as the one record after the points, to the end of the file; LAS 1.4 as
  // one of the EVLRs. It moves with the points.
  const std::uint64_t points_end = points_at + point_bytes;
  std::uint64_t waveform_at = 0;
  if (hd.version_minor >= 3 && (hd.global_encoding & 2u)) std::memcpy(&waveform_at, head.data() + 227, 8);
  std::optional<std::uint64_t> waveform_moved_to;
  if (hd.version_minor == 3 && waveform_at != 0) {
    const std::uint64_t file_size = std::filesystem::file_size(input);
    if (waveform_at < hd.offset_to_points || waveform_at >= file_size)
      throw FormatError(input, 227, "the waveform data record's start " + std::to_string(waveform_at) +
                                        " lies outside the file's data (" + std::to_string(hd.offset_to_points) + ".." +
                                        std::to_string(file_size) + ")");
    copy_bytes(in, input, waveform_at, file_size - waveform_at, out);
    waveform_moved_to = points_end;
  }
  // EVLRs (LAS 1.4): copied raw, 60-byte header and data, after the points.
  std::uint32_t evlr_count = 0;
  std::uint64_t evlr_at = points_end;
  for (const LasVlr& v : hd.vlrs) {
    if (!v.extended || is_compression_record(v)) continue;
    if (waveform_at != 0 && v.offset - 60 == waveform_at) waveform_moved_to = evlr_at;
    copy_bytes(in, input, v.offset - 60, 60 + v.length, out);
    evlr_at += 60 + v.length;
    ++evlr_count;
  }
  if (waveform_moved_to) {
    if (std::fseek(out.stream(), 227, SEEK_SET) != 0 || std::fwrite(&*waveform_moved_to, 8, 1, out.stream()) != 1 ||
        std::fseek(out.stream(), 0, SEEK_END) != 0)
      throw IoError(output + ": cannot write the header's waveform record start");
  }
  if (hd.version_minor >= 4) {
    std::vector<std::uint8_t> evlr_fields(12);
    store(evlr_fields, 0, static_cast<std::uint64_t>(evlr_count ? points_end : 0));
    store(evlr_fields, 8, evlr_count);
    if (std::fseek(out.stream(), 235, SEEK_SET) != 0 || std::fwrite(evlr_fields.data(), 12, 1, out.stream()) != 1 ||
        std::fseek(out.stream(), 0, SEEK_END) != 0)
      throw IoError(output + ": cannot write the EVLR fields of the header");
  }
  out.commit();
}

}  // namespace vola::io
