// The CRS flags of every command that voxelises points (convert, tile): one spelling,
// one help text. --assign-crs relabels, --target-crs moves the points; the old --crs
// (which relabelled, and was taken for a reprojection) is still read, with a note.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include <CLI/CLI.hpp>

namespace vola::cli {

// grid_flags: the flags that are then in the target CRS's units, for the help.
void add_crs_options(CLI::App& cmd, std::string& assign_crs, std::string& target_crs, bool& allow_geographic,
                     const std::string& grid_flags);

// The summaries' "crs:" line for a CRS given by WKT (or, with none, by EPSG code): its
// name, code, kind, unit and vertical part as PROJ reads them (what `vola info` prints);
// empty when there is none or PROJ cannot read it.
std::string crs_summary_line(const std::optional<std::uint32_t>& epsg, const std::string& wkt);

}  // namespace vola::cli
