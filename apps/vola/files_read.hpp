// The files a command reads for an input that may be a tile set (render, plan).
#pragma once

#include <string>
#include <vector>

namespace vola::cli {

// `path` itself, and for a tile index every tile and overview it names: an output over
// one of them replaced a tile the command had just read.
std::vector<std::string> files_read(const std::string& path);

}  // namespace vola::cli
