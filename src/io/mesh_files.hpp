// Mesh formats simple enough to read natively, where Assimp (5.2) read real files wrong:
// OFF, whose '#' comment lines among the faces it counted as faces (CGAL's verbose
// writer puts "# 6 facets" before them: a face lost per comment line) and whose face
// indices it clamped to the last vertex instead of refusing them; STL, whose ASCII
// files with upper-case keywords ("SOLID", "FACET NORMAL", as Unity and DEFORM write
// them) and binary files with bytes after the declared triangles (or a count of 0) it
// refused with "Failed to determine STL storage representation".
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "vola/io/input.hpp"

namespace vola::io {

// OFF (Geomview's, and ModelNet's): an optional [ST][C][N][4][n]OFF keyword (counts may
// follow it on its line, or be glued to it: "OFF8 6 0"), the vertex, face and edge
// counts, one vertex a line (x y z first; w divides them in 4OFF), one face a line (its
// corner count, the corners, an optional colour). '#' starts a comment anywhere.
// Polygons are cut into triangles (polygon_triangles.hpp); a face of one or two corners
// is a point or a line (a degenerate triangle). Throws FormatError naming the line and
// its byte offset for a corner out of range, a face line cut short, fewer or more lines
// than the header declares, or a binary OFF.
std::vector<Triangle> parse_off(std::span<const std::uint8_t> bytes, const std::string& name);

// STL, binary or ASCII. Binary when the file's size is 84 + 50 x the header's count (whatever
// its first bytes say: binary headers often begin with "solid"); ASCII when it begins
// with "solid" in any case; else binary whose count the size holds (bytes after the
// triangles are ignored, a count of 0 with a whole number of triangles after the header
// is taken from the size). Keywords of ASCII files are read in any case; a facet cut
// short is refused naming its line. Coordinates are 32-bit floats, as the format defines
// them.
std::vector<Triangle> parse_stl(std::span<const std::uint8_t> bytes, const std::string& name);

}  // namespace vola::io
