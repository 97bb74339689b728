// A list of scans with their poses, one per line:
//
//   FILE tx ty tz qx qy qz qw
//
// FILE holds points in the sensor frame (relative paths are relative to the list's
// folder); the pose maps sensor to world: p_world = R(q) p_sensor + t, so t is the sensor
// origin in the world. Blank lines and lines starting with '#' are skipped. FILE may not
// contain spaces.
#pragma once

#include <array>
#include <span>
#include <string>
#include <vector>

#include "vola/frame.hpp"

namespace vola::map {

struct Pose {
  Point translation{0, 0, 0};
  std::array<double, 4> rotation{0, 0, 0, 1};  // unit quaternion qx qy qz qw

  // Rotates then translates xyz (x y z per point) in place.
  void apply(std::span<double> xyz) const noexcept;
};

struct ScanEntry {
  std::string file;  // resolved against the list's folder
  Pose pose;
  int line = 0;      // 1-based, for messages
};

// Parses a list's text; `folder` resolves relative paths and `name` labels errors.
// Throws FormatError "<name>: line N: <cause>" for a line without 8 fields, a number that
// does not parse or is not finite, or a quaternion whose norm is not 1 within 1e-3 (it is
// then normalized). The files are not opened here.
std::vector<ScanEntry> parse_scan_list(const std::string& text, const std::string& folder, const std::string& name);
// Reads and parses a list file; throws IoError when it cannot be read.
std::vector<ScanEntry> read_scan_list(const std::string& path);

}  // namespace vola::map
