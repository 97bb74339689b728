#include "column_names.hpp"

#include "vola/io/column_reduction.hpp"

#include <cstdint>

#include <cctype>
#include <utility>

namespace vola::io {

namespace {

// Whether `text` is well-formed UTF-8 (RFC 3629: no overlong forms, no surrogates, at
// most U+10FFFF).
bool is_utf8(std::string_view text) {
  for (std::size_t i = 0; i < text.size();) {
    const auto c = static_cast<unsigned char>(text[i]);
    const int length = c < 0x80 ? 1 : (c >> 5) == 0x6 ? 2 : (c >> 4) == 0xe ? 3 : (c >> 3) == 0x1e ? 4 : 0;
    if (length == 0 || i + length > text.size()) return false;
    std::uint32_t point = length == 1 ? c : c & (0x7fu >> length);
    for (int k = 1; k < length; ++k) {
      const auto t = static_cast<unsigned char>(text[i + k]);
      if ((t >> 6) != 0x2) return false;
      point = (point << 6) | (t & 0x3fu);
    }
    static constexpr std::uint32_t kLeast[] = {0, 0, 0x80, 0x800, 0x10000};
    if (point < kLeast[length] || point > 0x10ffff || (point >= 0xd800 && point <= 0xdfff)) return false;
    i += static_cast<std::size_t>(length);
  }
  return true;
}

}  // namespace

std::string utf8_name(std::string_view name) {
  if (is_utf8(name)) return std::string(name);
  std::string out;
  for (const char ch : name) {
    const auto c = static_cast<unsigned char>(ch);
    if (c < 0x80) {
      out += ch;
    } else {
      out += static_cast<char>(0xc0 | (c >> 6));
      out += static_cast<char>(0x80 | (c & 0x3f));
    }
  }
  return out;
}

std::string point_column_name(std::string_view raw) {
  const std::string utf8 = utf8_name(raw);
  const std::string_view field = utf8;
  std::string lower, key;
  for (const char c : field) {
    const char l = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    lower += l;
    if (l != '_') key += l;
  }
  static constexpr std::pair<std::string_view, std::string_view> kNames[] = {
      {"returnnumber", "return_number"},
      {"numberofreturns", "number_of_returns"},
      {"scandirectionflag", "scan_direction_flag"},
      {"edgeofflightline", "edge_of_flight_line"},
      {"scananglerank", "scan_angle_rank"},
      {"userdata", "user_data"},
      {"pointsourceid", "point_source_id"},
      {"gpstime", "gps_time"},
      {"classflags", "classification_flags"},  // PDAL's names of the LAS 1.4 fields
      {"scanchannel", "scanner_channel"},
      {"scannerchannel", "scanner_channel"},
      {"keypoint", "key_point"},
      {"infrared", "nir"},
      {"r", "red"},
      {"g", "green"},
      {"b", "blue"},
  };
  for (const auto& [spelling, name] : kNames)
    if (key == spelling) return std::string(name);
  return lower;
}

bool names_identifiers(std::string_view field) {
  const auto lower = [](char c) { return std::islower(static_cast<unsigned char>(c)) != 0; };
  const auto digit = [](char c) { return std::isdigit(static_cast<unsigned char>(c)) != 0; };
  const auto separator = [](char c) { return c == '_' || c == ' ' || c == '-' || c == '.'; };
  if (field == "id" || field == "ID" || field == "Id") return true;
  if (field.size() < 3) return false;
  const std::string_view tail = field.substr(field.size() - 2);
  const char before = field[field.size() - 3];
  // treeID, OriginId, Segment3ID, tree_id, cluster-id; not geoid, centroid, GEOID (a
  // geoid height is a measurement), nor any word that merely ends in "id".
  if (tail == "ID" || tail == "Id") return lower(before) || digit(before) || separator(before);
  if (tail == "id" || tail == "iD") return separator(before);
  return false;
}

Reduction point_column_reduction(const std::string& column, std::string_view field) {
  if (column == "classification" || column == "class" || column == "label" || column == "scalar_classification" ||
      column == "cluster" || column == "segment" || column == "instance" || names_identifiers(field))
    return Reduction::majority;
  if (column == "number_of_returns") return Reduction::max;
  return Reduction::mean;
}

Reduction default_reduction(std::string_view name) { return point_column_reduction(point_column_name(name), name); }

}  // namespace vola::io
