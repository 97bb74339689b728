// PLY (Stanford polygon format): ascii, binary_little_endian and binary_big_endian,
// any element and property layout. The vertex element gives points (x y z, and
// red/green/blue colours when present); a face element (vertex_indices or
// vertex_index lists, polygons triangulated as fans) makes the input a mesh as well.
// Every other element and property, list or scalar, is skipped.
#pragma once

#include <cstdint>
#include <span>
#include <string>

#include "vola/io/input.hpp"

namespace vola::io {

// Input::cloud holds the vertices (attributes red/green/blue, u16 mean, with
// `options.attributes`; payload words R | G << 8 | B << 16 with `options.payload`);
// Input::triangles the faces, if the file has any. Throws FormatError with the file
// name and byte offset (and the line in ascii files) on anything malformed.
Input parse_ply(std::span<const std::uint8_t> bytes, const std::string& name, const InputOptions& options = {});
Input read_ply(const std::string& path, const InputOptions& options = {});

}  // namespace vola::io
