// The readers of small-to-medium interchange formats (PLY, PCD, KITTI, binvox) parse
// from memory so that the same code serves files and the fuzzer.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace vola::io {

// The whole file; throws IoError when it cannot be opened or read.
std::vector<std::uint8_t> read_file_bytes(const std::string& path);

}  // namespace vola::io
