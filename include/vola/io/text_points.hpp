// Points from text: XYZ/TXT/CSV, one point per line, columns separated by spaces,
// tabs, commas or semicolons. Lines starting with '#' or '//' and empty lines are
// skipped.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "vola/builder.hpp"

namespace vola::io {

struct TextColumns {
  int x = 0, y = 1, z = 2;  // 0-based column indices
  // Payload bytes, byte 0 first: each column's value must be an integer 0..255
  // (the reference's xyz2vola). Empty: no payload from the file.
  std::vector<int> payload;
  // Further columns kept as attributes (reduced per voxel).
  std::vector<PointAttribute> attributes;  // names/types/reductions; values filled in
  std::vector<int> attribute_columns;
  int skip_lines = 0;  // header lines to skip (txt2vola skips 1)
};

// Number of columns on the first data line after `skip_lines` lines (0 for none).
int count_text_columns(const std::string& path, int skip_lines);

// Reads the whole file; `progress(bytes_done, bytes_total)` is called now and then.
// Throws FormatError "<file>: line N: ..." (with the byte offset) on a bad line.
PointCloud read_text_points(const std::string& path, const TextColumns& columns,
                            const std::function<void(std::uint64_t, std::uint64_t)>& progress = {});

}  // namespace vola::io
