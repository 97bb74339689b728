// The vertex and face counts of an OFF header exactly as Assimp's OFF importer reads
// them, so that counts the file cannot hold are refused before Assimp allocates them
// (it allocates both arrays, up to 52 bytes a vertex and 16 a face, from the header).
//
// Assimp's grammar (code/AssetLib/OFF/OFFLoader.cpp, 5.2): after blanks and '#' lines,
// optional prefixes ST, C, N, 4, n in that order, each one character or two, taken
// whatever follows them; then "OFF" or nothing; a dimension when the n prefix was
// there; then the vertex, face and edge counts, read as unsigned 32-bit integers that
// wrap ("4294967297" is 1). Reading it any other way (looking for "OFF" first, or
// saturating) lets a file whose counts Assimp reads differently through.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string_view>

namespace vola::io {

struct OffCounts {
  std::uint32_t vertices = 0;
  std::uint32_t faces = 0;
  std::size_t vertices_at = 0;  // byte offset of the vertex count
};

// The counts Assimp would read from `text` (the whole file), or nullopt when Assimp
// refuses the header itself before allocating anything.
std::optional<OffCounts> off_header_counts(std::string_view text);

}  // namespace vola::io
