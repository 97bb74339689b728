// Leica PTX, the text interchange format of terrestrial scanners (Cyclone, FARO SCENE,
// CloudCompare, LAStools): one or more scans, each a header of ten lines (columns, rows,
// the scanner's registered position and axes, a 4 x 4 transformation matrix) and then
// columns x rows lines of "x y z intensity [red green blue]" in the scanner's frame, a
// point of 0 0 0 standing for no return.
#pragma once

#include <string>

#include "vola/io/input.hpp"

namespace vola::io {

// Every scan's returns in one cloud, each moved by its matrix as a row vector times the
// matrix (the last row holds the translation: [x y z 1] M, as Cyclone, CloudCompare and
// LAStools apply it); points at 0 0 0 are left out and counted in Input::not_finite.
// Columns: intensity (f32, mean) and, when every scan has them, red/green/blue (0..255;
// --nbits 1 payload bytes R, G, B). A header or point line that is not what the format
// says, or a scan that ends before its columns x rows points, is an error naming the
// line and its byte.
Input read_ptx(const std::string& path, const InputOptions& options);

}  // namespace vola::io
