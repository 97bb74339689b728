// Internal to the conversion pipeline: the CRS rules, decided once for every front end.
#pragma once

#include <cstdint>
#include <optional>

#include "vola/convert.hpp"
#include "vola/io/input.hpp"

namespace vola::convert_detail {

// The EPSG code the conversion knows: the one the options give, else the input's (stated,
// or found by PROJ from the input's WKT).
std::optional<std::uint32_t> known_epsg(const ConvertOptions& options, io::Input& input);

// The code the VOLA header carries: the known one, else the reference's default (2000).
std::uint32_t header_epsg(const std::optional<std::uint32_t>& known);

// The tree's georeference after the build: the header code, the WGS84 lat/lon of the
// bbox centre (through PROJ; 0, 0 when PROJ cannot place a CRS nobody named), and the CRS
// as WKT in the extension whenever it is known, except for a toolkit conversion of
// CRS-less input, which stays byte-identical to the reference's file.
void georeference(Tree& tree, const ConvertOptions& options, const io::Input& input,
                  const std::optional<std::uint32_t>& known, Quantization quantization);

}  // namespace vola::convert_detail
