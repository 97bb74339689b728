// LAS point records (any point format 0-10) into a LasChunk's columns.
#include "las_format.hpp"
#include "vola/io/las.hpp"
#include "vola/little_endian.hpp"

namespace vola::io {

void decode_las_records(const LasHeader& hd, std::span<const std::uint8_t> records, LasChunk& chunk) {
  const std::size_t length = hd.record_length, m = records.size() / length, at = chunk.size();
  const std::size_t n = at + m;
  const bool extended = hd.extended_format();
  const bool rgb = hd.has_rgb(), gps = hd.has_gps_time();
  // Byte offsets of the optional fields inside a record.
  const std::size_t gps_at = extended ? 22 : 20;
  const std::size_t rgb_at = extended ? 30 : (hd.point_format == 2 ? 20 : 28);
  chunk.extra.resize(hd.extra_fields.size());
  chunk.xyz.resize(3 * n);
  chunk.intensity.resize(n);
  chunk.return_number.resize(n);
  chunk.number_of_returns.resize(n);
  chunk.classification.resize(n);
  chunk.user_data.resize(n);
  chunk.point_source_id.resize(n);
  if (gps) chunk.gps_time.resize(n);
  if (rgb) {
    chunk.red.resize(n);
    chunk.green.resize(n);
    chunk.blue.resize(n);
  }
  for (auto& e : chunk.extra) e.resize(n);
  for (std::size_t k = 0; k < m; ++k) {
    const std::uint8_t* r = records.data() + k * length;
    const std::size_t i = at + k;
    for (int a = 0; a < 3; ++a)
      chunk.xyz[3 * i + a] = static_cast<double>(load_le<std::int32_t>(r + 4 * a)) * hd.scale[a] + hd.offset[a];
    chunk.intensity[i] = load_le<std::uint16_t>(r + 12);
    if (extended) {
      chunk.return_number[i] = r[14] & 15u;
      chunk.number_of_returns[i] = r[14] >> 4;
      chunk.classification[i] = r[16];
      chunk.user_data[i] = r[17];
      chunk.point_source_id[i] = load_le<std::uint16_t>(r + 20);
    } else {
      chunk.return_number[i] = r[14] & 7u;
      chunk.number_of_returns[i] = (r[14] >> 3) & 7u;
      chunk.classification[i] = r[15] & 31u;  // bits 5-7 are synthetic/key-point/withheld flags
      chunk.user_data[i] = r[17];
      chunk.point_source_id[i] = load_le<std::uint16_t>(r + 18);
    }
    if (gps) chunk.gps_time[i] = load_le<double>(r + gps_at);
    if (rgb) {
      chunk.red[i] = load_le<std::uint16_t>(r + rgb_at);
      chunk.green[i] = load_le<std::uint16_t>(r + rgb_at + 2);
      chunk.blue[i] = load_le<std::uint16_t>(r + rgb_at + 4);
    }
    for (std::size_t f = 0; f < hd.extra_fields.size(); ++f) {
      const auto& field = hd.extra_fields[f];
      chunk.extra[f][i] = las::extra_field_value(r, field);
    }
  }
}

}  // namespace vola::io
