// The CRS flags of every command that voxelises points (convert, tile): one spelling,
// one help text. --assign-crs relabels, --target-crs moves the points; the old --crs
// (which relabelled, and was taken for a reprojection) is still read, with a note.
#pragma once

#include <string>

#include <CLI/CLI.hpp>

namespace vola::cli {

// grid_flags: the flags that are then in the target CRS's units, for the help.
void add_crs_options(CLI::App& cmd, std::string& assign_crs, std::string& target_crs, bool& allow_geographic,
                     const std::string& grid_flags);

}  // namespace vola::cli
