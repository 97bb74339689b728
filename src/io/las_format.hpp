// Internal to the LAS reader: facts of the format that the header parser, the record
// decoder and the attribute columns share.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

#include <limits>

#include "vola/io/las.hpp"
#include "vola/little_endian.hpp"

namespace vola::io::las {

// Minimum record length of each point data record format (ASPRS LAS 1.4 R15).
constexpr std::uint16_t kMinRecordLength[11] = {20, 28, 26, 34, 57, 63, 30, 36, 38, 59, 67};
// GeoKey value meaning "user-defined" (no EPSG code).
constexpr std::uint32_t kUserDefined = 32767;

// A fixed-size text field: up to the first NUL, trailing spaces removed.
inline std::string text(const std::uint8_t* p, std::size_t n) {
  std::string s(reinterpret_cast<const char*>(p), n);
  const auto end = s.find('\0');
  if (end != std::string::npos) s.resize(end);
  while (!s.empty() && s.back() == ' ') s.pop_back();
  return s;
}

// Bytes of one value of a scalar extra-bytes type 1..10.
inline std::size_t extra_size(std::uint8_t type) {
  static constexpr std::size_t sizes[11] = {0, 1, 1, 2, 2, 4, 4, 8, 8, 4, 8};
  return type <= 10 ? sizes[type] : 0;
}

// One extra-bytes value of scalar type 1..10 as a double.
inline double extra_value(const std::uint8_t* p, std::uint8_t type) {
  switch (type) {
    case 1: return load_le<std::uint8_t>(p);
    case 2: return load_le<std::int8_t>(p);
    case 3: return load_le<std::uint16_t>(p);
    case 4: return load_le<std::int16_t>(p);
    case 5: return load_le<std::uint32_t>(p);
    case 6: return load_le<std::int32_t>(p);
    case 7: return static_cast<double>(load_le<std::uint64_t>(p));
    case 8: return static_cast<double>(load_le<std::int64_t>(p));
    case 9: return load_le<float>(p);
    case 10: return load_le<double>(p);
    default: return 0.0;
  }
}

// An extra-bytes field's value in a record: scaled and offset, NaN for its no-data value.
inline double extra_field_value(const std::uint8_t* record, const LasExtraField& f) {
  const double stored = extra_value(record + f.offset, f.data_type);
  if (f.no_data && stored == *f.no_data) return std::numeric_limits<double>::quiet_NaN();
  return stored * f.scale + f.add;
}

// Whether a path names a LAZ file (".laz", any case; ".copc.laz" too).
inline bool laz_path(const std::string& path) {
  if (path.size() < 4) return false;
  std::string ext = path.substr(path.size() - 4);
  for (char& c : ext) c = static_cast<char>(c >= 'A' && c <= 'Z' ? c - 'A' + 'a' : c);
  return ext == ".laz";
}

}  // namespace vola::io::las
