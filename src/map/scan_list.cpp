#include "vola/map/scan_list.hpp"

#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "vola/error.hpp"

namespace vola::map {

namespace {

namespace fs = std::filesystem;

std::vector<std::string> fields_of(const std::string& line) {
  std::istringstream in(line);
  std::vector<std::string> fields;
  for (std::string f; in >> f;) fields.push_back(f);
  return fields;
}

// from_chars, not stod: no locale, and "1.5x" is an error rather than 1.5.
bool parse_number(const std::string& text, double& out) {
  const char* end = text.data() + text.size();
  const auto [ptr, ec] = std::from_chars(text.data(), end, out);
  return ec == std::errc() && ptr == end && std::isfinite(out);
}

ScanEntry parse_line(const std::vector<std::string>& fields, const fs::path& folder, const std::string& name,
                     int line) {
  const auto fail = [&](const std::string& cause) {
    throw FormatError(name, std::nullopt, "line " + std::to_string(line) + ": " + cause);
  };
  if (fields.size() != 8)
    fail("expected FILE tx ty tz qx qy qz qw (8 fields), got " + std::to_string(fields.size()));
  static const char* const kNames[7] = {"tx", "ty", "tz", "qx", "qy", "qz", "qw"};
  double v[7];
  for (int n = 0; n < 7; ++n)
    if (!parse_number(fields[static_cast<std::size_t>(n) + 1], v[n]))
      fail(std::string(kNames[n]) + " is not a finite number: '" + fields[static_cast<std::size_t>(n) + 1] + "'");
  const double norm = std::sqrt(v[3] * v[3] + v[4] * v[4] + v[5] * v[5] + v[6] * v[6]);
  // Text rounds a unit quaternion's digits; a larger error is a wrong column, not rounding.
  if (!(std::abs(norm - 1.0) <= 1e-3)) fail("the quaternion qx qy qz qw has norm " + std::to_string(norm) + ", not 1");
  ScanEntry entry;
  const fs::path file(fields[0]);
  entry.file = (file.is_absolute() ? file : folder / file).string();
  entry.pose.translation = {v[0], v[1], v[2]};
  entry.pose.rotation = {v[3] / norm, v[4] / norm, v[5] / norm, v[6] / norm};
  entry.line = line;
  return entry;
}

}  // namespace

void Pose::apply(std::span<double> xyz) const noexcept {
  const auto [x, y, z, w] = rotation;
  const double r[3][3] = {{1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)},
                          {2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)},
                          {2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)}};
  for (std::size_t n = 0; n + 2 < xyz.size(); n += 3) {
    const double p[3] = {xyz[n], xyz[n + 1], xyz[n + 2]};
    for (int a = 0; a < 3; ++a)
      xyz[n + static_cast<std::size_t>(a)] = r[a][0] * p[0] + r[a][1] * p[1] + r[a][2] * p[2] + translation[a];
  }
}

std::vector<ScanEntry> parse_scan_list(const std::string& text, const std::string& folder, const std::string& name) {
  std::vector<ScanEntry> entries;
  std::istringstream in(text);
  int line = 0;
  for (std::string row; std::getline(in, row);) {
    ++line;
    const std::vector<std::string> fields = fields_of(row);
    if (fields.empty() || fields[0][0] == '#') continue;
    entries.push_back(parse_line(fields, fs::path(folder), name, line));
  }
  if (entries.empty()) throw FormatError(name, std::nullopt, "no scans listed");
  return entries;
}

std::vector<ScanEntry> read_scan_list(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw IoError("cannot read the scan list " + path);
  std::ostringstream text;
  text << in.rdbuf();
  return parse_scan_list(text.str(), fs::path(path).parent_path().string(), path);
}

}  // namespace vola::map
