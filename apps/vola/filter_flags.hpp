// The point-filter flags of every command that reads points (convert, translate, tile):
// --where, --filter, --crop and --crop-polygon, each appending one stage to the list
// in the order they are given (so `--filter smrf --filter hag --where "HeightAboveGround > 2"`
// classifies, measures, then selects). The stage strings are those of vola/filters/stages.hpp.
#pragma once

#include <string>
#include <vector>

#include <CLI/CLI.hpp>

namespace vola::cli {

// `neighbour_stages`: whether the command runs the stages that need each point's neighbours
// (smrf, hag, outlier, voxel, poisson); vola tile, which reads chunk by chunk, does not.
void add_filter_options(CLI::App& cmd, std::vector<std::string>& stages, bool neighbour_stages = true);

// The help footer's paragraph about the filters.
extern const char* const kFilterHelp;

}  // namespace vola::cli
