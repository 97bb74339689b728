// Internal to the conversion pipeline: point input read whole with every field, the
// filter stages of ConvertOptions::filters run on it, and the columns a conversion keeps.
#pragma once

#include <string>
#include <vector>

#include "vola/convert.hpp"
#include "vola/filters/stages.hpp"
#include "vola/io/input.hpp"

namespace vola::convert_detail {

// The input's points after the filters, with the attribute columns vola convert keeps
// for its format (LAS: those of io::las_attributes, plus columns the filters add such as
// height_above_ground; none without options.attributes). Each stage's counts go to
// `report`. Text input is read as without filters (`input`: its columns, the
// --attribute columns named), so that the filters see those names and the columns stay.
// Throws OptionError("filters", ...) for input that is not points.
io::Input read_filtered(const std::string& path, const io::InputFormat& format, const ConvertOptions& options,
                        const io::InputOptions& input, std::vector<filters::StageReport>& report);

// "smrf: 110000 -> 110000 points, 26411 ground".
std::string describe(const filters::StageReport& stage);

}  // namespace vola::convert_detail
