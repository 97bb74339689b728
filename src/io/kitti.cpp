#include "vola/io/kitti.hpp"

#include <cstring>

#include "file_bytes.hpp"
#include "vola/error.hpp"

namespace vola::io {

std::uint8_t kitti_reflectance_byte(float reflectance) noexcept {
  // binutils.normalize(val, -0.2, 1) in float64, stored back into the float32 array,
  // then multiplied by 255 as float32 and truncated by astype(int).
  const double r = reflectance;
  double normed = 0.0;
  if (r >= 1.0) normed = 1.0;
  else if (r <= -0.2) normed = 0.0;
  else if (r == r) normed = (r - -0.2) / (1.0 - -0.2);
  const float scaled = static_cast<float>(normed) * 255.0f;
  return static_cast<std::uint8_t>(scaled);
}

PointCloud parse_kitti(std::span<const std::uint8_t> bytes, const std::string& name, const InputOptions& options) {
  constexpr std::size_t kRecord = 16;
  if (bytes.size() % kRecord != 0)
    throw FormatError(name, bytes.size() - bytes.size() % kRecord,
                      "a KITTI scan is 16-byte records (x y z reflectance as float32), but the file has " +
                          std::to_string(bytes.size()) + " bytes, " + std::to_string(bytes.size() % kRecord) +
                          " past the last whole record");
  const std::size_t n = bytes.size() / kRecord;
  PointCloud cloud;
  cloud.xyz.resize(3 * n);
  PointAttribute* reflectance = nullptr;
  if (options.attributes) {
    cloud.attributes.push_back({"reflectance", ValueType::f32, Reduction::mean, {}});
    reflectance = &cloud.attributes.back();
    reflectance->values.resize(n);
  }
  if (options.payload) cloud.payload.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    float record[4];
    std::memcpy(record, bytes.data() + i * kRecord, kRecord);
    for (std::size_t a = 0; a < 3; ++a) cloud.xyz[3 * i + a] = record[a];
    if (reflectance) reflectance->values[i] = record[3];
    if (options.payload) cloud.payload[i] = std::uint64_t{kitti_reflectance_byte(record[3])} * 0x010101u;
  }
  if (options.progress) options.progress(bytes.size(), bytes.size());
  return cloud;
}

PointCloud read_kitti(const std::string& path, const InputOptions& options) {
  return parse_kitti(read_file_bytes(path), path, options);
}

}  // namespace vola::io
