// What the text and PLY writers share: attribute values as text, and column names
// made usable as whitespace-separated tokens.
#pragma once

#include <string>
#include <vector>

#include "vola/attributes.hpp"
#include "vola/tree.hpp"

namespace vola::io {

// Throws InvalidArgument unless every attribute column holds one value per voxel
// (writers index columns by voxel rank).
void require_complete_columns(const Tree& tree);

// One name per column: characters that are not printable ASCII, spaces, and the text
// reader's separators and quotes (, ; ") become '_' (a header "M3C2 distance","a,b" read
// back as one more column than the values), and a name equal to one in `taken` or to an
// earlier column's gets "_2", "_3"...
std::vector<std::string> token_names(const Attributes& attributes, std::vector<std::string> taken);
std::vector<std::string> token_names(const std::vector<std::string>& names, std::vector<std::string> taken);

// The text outputs' header line: "# x y z NAME..." (vola's XYZ, space-separated), or, for
// CSV, PDAL's writers.text header, "X","Y","Z","Intensity",...: the LAS dimensions in
// PDAL's spelling, which the text reader maps back to the same columns.
std::string text_header(const std::vector<std::string>& names, bool csv);

// The PLY property type of a column's values (64-bit integers, which PLY lacks: double).
const char* ply_type(ValueType type);

// The shortest text that reads back as the same double (vola::write_number).
void append_number(std::string& out, double value);
// A column's value at `rank` as text in the column's own type (64-bit integers exact).
void append_value(std::string& out, const AttributeColumn& column, std::size_t rank);

}  // namespace vola::io
