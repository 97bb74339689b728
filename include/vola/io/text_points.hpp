// Points from text: XYZ/TXT/CSV, one point per line, columns separated by spaces,
// tabs, commas or semicolons; every point line has as many columns as the first. A line
// with a semicolon, or with commas standing alone between digits in fields separated by
// spaces or tabs ("1,5;2,25;3", "1,5 2,25 3"), has decimal commas, as spreadsheets in
// most of Europe write them: its commas are decimal marks, not separators. Lines end with
// "\n" ("\r\n" too), or with "\r" alone when the file's first 64 KiB hold no "\n"; a
// UTF-8 byte order mark is passed over; in a .pts file (Leica), a line holding one
// integer is a scan's point count, passed over. Lines starting with '#' or '//' and empty lines are
// skipped. A first line of names (after `skip_lines`), as PDAL's writers.text
// ("X","Y","Z","Intensity"), CloudCompare (//X,Y,Z,R,G,B) and vola export
// (# x y z intensity) write it, is a header: never read as a point, and, when the
// columns are left to it (TextColumns::from_header), it says which columns are x, y and
// z and names every other column as an attribute.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <optional>
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
  // Take x, y, z and the attributes from a header line naming x, y and z, when the file
  // has one (the members above then describe a file without one).
  bool from_header = true;
  // With from_header: keep the header's other columns as attributes (false: x, y, z only).
  bool named_attributes = true;
  // With from_header: x, y and z are the columns above (--columns), not the header's; its
  // other named columns are still kept (--columns 1 2 3 on a header dropped them all).
  bool xyz_given = false;
};

// The column names of a header line (see above), or none when the first line after
// `skip_lines` holds values or does not name x, y and z. `line` is its number (1-based);
// `comment` whether it began with '#' or '//'. A file without one whose extension names
// its columns (Open3D's .xyzn: x y z nx ny nz; .xyzrgb: x y z red green blue, colours in
// 0..1) gets those names, as a comment at line 0.
struct TextHeader {
  std::vector<std::string> names;  // as written, quotes removed
  std::uint64_t line = 0;
  std::uint64_t offset = 0;  // the line's first byte in the file
  bool comment = false;
};
std::optional<TextHeader> read_text_header(const std::string& path, int skip_lines);

// The columns a header names: x, y, z by name (any case) and every other column as an
// attribute (f64; classification/class/label by majority, number_of_returns by maximum,
// red/green/blue as u16 when their values are whole 0..65535, the rest by mean), PDAL's
// spellings of LAS fields (ReturnNumber, GpsTime, ...) and CloudCompare's R, G, B under
// the LAS reader's names.
TextColumns text_columns_of(const TextHeader& header);
// The same with x, y and z in the given columns (0-based); the header's other named
// columns (not those it calls x, y, z) are the attributes.
TextColumns text_columns_of(const TextHeader& header, int x, int y, int z);
// The columns (0-based) a header names x, y and z, or none when it does not name all three.
std::optional<std::array<int, 3>> named_xyz_columns(const TextHeader& header);

// Number of columns on the first data line after `skip_lines` lines (0 for none).
int count_text_columns(const std::string& path, int skip_lines);

// Reads the whole file; `progress(bytes_done, bytes_total)` is called now and then.
// Throws FormatError "<file>: line N: ..." (with the byte offset) on a bad line.
PointCloud read_text_points(const std::string& path, const TextColumns& columns,
                            const std::function<void(std::uint64_t, std::uint64_t)>& progress = {});

}  // namespace vola::io
