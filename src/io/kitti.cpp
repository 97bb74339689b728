#include "vola/io/kitti.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>
#include <filesystem>

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
    throw FormatError(
        name, bytes.size() - bytes.size() % kRecord,
        "a KITTI scan is 16-byte records (x y z reflectance as float32), but the file has " +
            std::to_string(bytes.size()) + " bytes, " + std::to_string(bytes.size() % kRecord) +
            " past the last whole record" +
            (bytes.size() % 20 == 0 ? "; its size is a whole number of 20-byte records, as a nuScenes or Lyft sweep's "
                                      "(x y z intensity ring): give --format nuscenes"
                                    : std::string()));
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

PointCloud parse_nuscenes(std::span<const std::uint8_t> bytes, const std::string& name, const InputOptions& options) {
  constexpr std::size_t kRecord = 20;
  if (bytes.size() % kRecord != 0)
    throw FormatError(name, bytes.size() - bytes.size() % kRecord,
                      "a nuScenes sweep (.pcd.bin) is 20-byte records (x y z intensity ring as float32), but the file "
                      "has " +
                          std::to_string(bytes.size()) + " bytes, " + std::to_string(bytes.size() % kRecord) +
                          " past the last whole record");
  const std::size_t n = bytes.size() / kRecord;
  PointCloud cloud;
  cloud.xyz.resize(3 * n);
  if (options.attributes) {
    cloud.attributes.push_back({"intensity", ValueType::f32, Reduction::mean, {}});
    cloud.attributes.push_back({"ring", ValueType::u8, Reduction::majority, {}});
    for (auto& a : cloud.attributes) a.values.resize(n);
  }
  if (options.payload) cloud.payload.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    float record[5];
    std::memcpy(record, bytes.data() + i * kRecord, kRecord);
    for (std::size_t a = 0; a < 3; ++a) cloud.xyz[3 * i + a] = record[a];
    if (options.attributes) {
      cloud.attributes[0].values[i] = record[3];
      // A ring index outside a byte (or NaN) is not one: kept as 255, never wrapped.
      cloud.attributes[1].values[i] = record[4] >= 0 && record[4] <= 254 ? std::round(record[4]) : 255.0;
    }
    if (options.payload) {
      const float grey = record[3] >= 0 ? std::min(record[3], 255.0f) : 0.0f;  // NaN -> 0
      cloud.payload[i] = std::uint64_t{static_cast<std::uint8_t>(grey)} * 0x010101u;
    }
  }
  if (options.progress) options.progress(bytes.size(), bytes.size());
  return cloud;
}

bool is_nuscenes_sweep(const std::string& path) {
  std::string name = std::filesystem::path(path).filename().string();
  std::transform(name.begin(), name.end(), name.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return name.size() > 8 && name.ends_with(".pcd.bin");
}

PointCloud read_kitti(const std::string& path, const InputOptions& options) {
  if (is_nuscenes_sweep(path)) return parse_nuscenes(read_file_bytes(path), path, options);
  return parse_kitti(read_file_bytes(path), path, options);
}

}  // namespace vola::io
