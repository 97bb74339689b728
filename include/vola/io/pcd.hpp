// PCD (the Point Cloud Library's format), versions .5 to 0.7: DATA ascii, binary and
// binary_compressed (LZF, one column per field). Fields of types F/I/U of 1, 2, 4 or
// 8 bytes with any COUNT; names compared without case.
#pragma once

#include <cstdint>
#include <span>
#include <string>

#include "vola/builder.hpp"
#include "vola/io/input.hpp"

namespace vola::io {

// x y z of every point whose coordinates are finite (organized clouds mark missing
// points with NaN). With `options.attributes`: red/green/blue (u16, mean) from a packed
// rgb/rgba field or from red/green/blue fields, and intensity (f32, mean); with
// `options.payload`: words R | G << 8 | B << 16 when the cloud has colours. Throws
// FormatError with the file name and byte offset (and the line in ascii data).
// `not_finite`, when given, receives the number of points left out.
PointCloud parse_pcd(std::span<const std::uint8_t> bytes, const std::string& name, const InputOptions& options = {},
                     std::uint64_t* not_finite = nullptr);
PointCloud read_pcd(const std::string& path, const InputOptions& options = {}, std::uint64_t* not_finite = nullptr);

}  // namespace vola::io
