// Internal to the conversion pipeline: ConvertOptions translated into what the readers
// and the builder take.
#pragma once

#include <cstdint>
#include <string>

#include "vola/builder.hpp"
#include "vola/convert.hpp"
#include "vola/io/text_points.hpp"

namespace vola::convert_detail {

struct TextAttributeSpec {
  PointAttribute attribute;  // name, type, reduction
  int column = 0;            // counting from 1
};

// "NAME=COLUMN[:TYPE[:REDUCTION]]"; throws OptionError("text_attributes", ...).
TextAttributeSpec parse_text_attribute(const std::string& spec);

// The quantization the options ask for (grid when a voxel size or origin is given).
Quantization quantization_of(const ConvertOptions& options);

// The builder's options; `epsg` is the code the header will carry.
BuildOptions build_options(const ConvertOptions& options, std::uint32_t epsg);

// Text input: which columns are x y z, payload bytes and attributes (0-based).
io::TextColumns text_columns(const std::string& input, const ConvertOptions& options);

}  // namespace vola::convert_detail
