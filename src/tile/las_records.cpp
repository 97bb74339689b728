#include "las_records.hpp"

#include <numeric>

#include "vola/little_endian.hpp"

namespace vola::tile {

void las_record_xyz(const io::LasHeader& hd, std::span<const std::uint8_t> records, std::vector<double>& xyz) {
  const std::size_t length = hd.record_length, n = records.size() / length;
  xyz.resize(3 * n);
  double* out = xyz.data();
  const std::uint8_t* r = records.data();
  // Every point format starts with X, Y, Z as little-endian int32 (ASPRS LAS 1.4, 2.6).
  for (std::size_t i = 0; i < n; ++i, r += length, out += 3)
    for (int a = 0; a < 3; ++a) out[a] = static_cast<double>(load_le<std::int32_t>(r + 4 * a)) * hd.scale[a] + hd.offset[a];
}

void las_record_points(const io::LasHeader& hd, std::span<const std::uint8_t> records, std::vector<double>& xyz,
                       std::vector<std::vector<double>>& values) {
  las_record_xyz(hd, records, xyz);
  thread_local std::vector<std::uint32_t> every;  // record i is point i
  const std::size_t n = records.size() / hd.record_length;
  if (every.size() < n) {
    every.resize(n);
    std::iota(every.begin(), every.end(), 0u);
  }
  io::las_record_attribute_values(hd, records.data(), std::span<const std::uint32_t>(every.data(), n), values);
}

}  // namespace vola::tile
