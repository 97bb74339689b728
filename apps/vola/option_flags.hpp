// Library errors name options as the library's structs do (OptionError::option(), and
// `name` in backquotes inside the cause); the user typed flags. One table for every
// subcommand: a member's flag is --name with dashes for underscores unless listed.
#pragma once

#include <string>

#include "vola/error.hpp"

namespace vola::cli {

// "voxel_size" -> "--voxel-size", "epsg" -> "--assign-crs", ...
std::string flag_of(const std::string& option);

// "voxel_size: grid quantization needs a `voxel_size` or a `depth`" ->
// "--voxel-size: grid quantization needs a --voxel-size or a --depth"
std::string in_flags(const OptionError& error);
// A library message with each `member` named as its flag (warnings, causes).
std::string with_flags(std::string text);

}  // namespace vola::cli
