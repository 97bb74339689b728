#include "export_columns.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cstdint>
#include <cstring>
#include <string_view>
#include <utility>

#include "vola/error.hpp"
#include "vola/number_text.hpp"

namespace vola::io {

namespace {

template <class T>
void append_raw(std::string& out, const std::byte* p) {
  T v;
  std::memcpy(&v, p, sizeof(T));
  char s[32];
  const auto r = std::to_chars(s, s + sizeof s, v);
  out.append(s, r.ptr);
}

}  // namespace

void require_complete_columns(const Tree& tree) {
  for (const auto& column : tree.attributes().columns())
    if (column.size() != tree.voxel_count())
      throw InvalidArgument("attribute '" + column.name() + "' has " + std::to_string(column.size()) +
                            " values for " + std::to_string(tree.voxel_count()) + " voxels");
}

std::vector<std::string> token_names(const std::vector<std::string>& names, std::vector<std::string> taken) {
  std::vector<std::string> out;
  for (std::string name : names) {
    for (char& c : name)
      if (c <= ' ' || c > '~' || c == ',' || c == ';' || c == '"') c = '_';
    if (name.empty()) name = "attribute";
    std::string unique = name;
    for (int n = 2; std::find(taken.begin(), taken.end(), unique) != taken.end(); ++n)
      unique = name + "_" + std::to_string(n);
    taken.push_back(unique);
    out.push_back(std::move(unique));
  }
  return out;
}

std::vector<std::string> token_names(const Attributes& attributes, std::vector<std::string> taken) {
  std::vector<std::string> names;
  for (const auto& column : attributes.columns()) names.push_back(column.name());
  return token_names(names, std::move(taken));
}

std::string text_header(const std::vector<std::string>& names, bool csv) {
  if (!csv) {
    std::string line = "# x y z";
    for (const auto& name : names) line += " " + name;
    return line + '\n';
  }
  static constexpr std::pair<std::string_view, std::string_view> kPdalNames[] = {
      {"intensity", "Intensity"},
      {"return_number", "ReturnNumber"},
      {"number_of_returns", "NumberOfReturns"},
      {"scan_direction_flag", "ScanDirectionFlag"},
      {"edge_of_flight_line", "EdgeOfFlightLine"},
      {"classification", "Classification"},
      {"scan_angle_rank", "ScanAngleRank"},
      {"user_data", "UserData"},
      {"point_source_id", "PointSourceId"},
      {"gps_time", "GpsTime"},
      {"red", "Red"},
      {"green", "Green"},
      {"blue", "Blue"},
      {"classification_flags", "ClassFlags"},
      {"synthetic", "Synthetic"},
      {"key_point", "KeyPoint"},
      {"withheld", "Withheld"},
      {"overlap", "Overlap"},
      {"scanner_channel", "ScanChannel"},
      {"nir", "Infrared"},
  };
  // No name twice once spelled as PDAL does, case aside (a PLY's intensity and Intensity
  // both became "Intensity", and the reader kept one): later ones get _2, _3, ...
  const auto lower = [](std::string s) {
    for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return s;
  };
  std::vector<std::string> taken{"x", "y", "z"};
  std::string line = "\"X\",\"Y\",\"Z\"";
  for (const auto& name : names) {
    std::string shown = name;
    for (const auto& [ours, pdal] : kPdalNames)
      if (name == ours) shown = std::string(pdal);
    std::string unique = shown;
    for (int n = 2; std::find(taken.begin(), taken.end(), lower(unique)) != taken.end(); ++n)
      unique = shown + "_" + std::to_string(n);
    taken.push_back(lower(unique));
    line += ",\"" + unique + "\"";
  }
  return line + '\n';
}

const char* ply_type(ValueType type) {
  switch (type) {
    case ValueType::u8: return "uchar";
    case ValueType::u16: return "ushort";
    case ValueType::u32: return "uint";
    case ValueType::i8: return "char";
    case ValueType::i16: return "short";
    case ValueType::i32: return "int";
    case ValueType::f32: return "float";
    case ValueType::u64:  // PLY has no 64-bit integers
    case ValueType::i64:
    case ValueType::f64: return "double";
  }
  return "double";
}

void append_number(std::string& out, double value) {
  char s[kNumberTextSize];
  out.append(s, write_number(s, value));
}

void append_value(std::string& out, const AttributeColumn& column, std::size_t rank) {
  const std::byte* p = column.bytes().data() + rank * size_of(column.type());
  switch (column.type()) {
    case ValueType::u8: return append_raw<std::uint8_t>(out, p);
    case ValueType::u16: return append_raw<std::uint16_t>(out, p);
    case ValueType::u32: return append_raw<std::uint32_t>(out, p);
    case ValueType::u64: return append_raw<std::uint64_t>(out, p);
    case ValueType::i8: return append_raw<std::int8_t>(out, p);
    case ValueType::i16: return append_raw<std::int16_t>(out, p);
    case ValueType::i32: return append_raw<std::int32_t>(out, p);
    case ValueType::i64: return append_raw<std::int64_t>(out, p);
    case ValueType::f32: return append_raw<float>(out, p);
    case ValueType::f64: return append_raw<double>(out, p);
  }
}

}  // namespace vola::io
