// Checks of numeric options that say what the option wants. CLI11's PositiveNumber and
// NonNegativeNumber answer "Value 0 not in range 0.000000 to 1797693134862315708...",
// the bounds of a double printed in full.
#pragma once

#include <CLI/CLI.hpp>

namespace vola::cli {

// "--voxel-size: must be a positive number, not 0"; "... not a number: 'abc'".
CLI::Validator positive_number();
CLI::Validator non_negative_number();

}  // namespace vola::cli
