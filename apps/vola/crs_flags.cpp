#include "crs_flags.hpp"

#include <cstdio>

#include "vola/error.hpp"
#include "vola/geo/crs.hpp"

namespace vola::cli {

void add_crs_options(CLI::App& cmd, std::string& assign_crs, std::string& target_crs, bool& allow_geographic,
                     const std::string& grid_flags) {
  cmd.add_option("--assign-crs", assign_crs,
                 "The inputs' CRS (EPSG code such as 32610 or EPSG:32610, AUTHORITY:CODE, WKT, PROJJSON or a PROJ "
                 "string; not a name), relabelling them without moving a point (default: what the inputs say; a "
                 "warning when they say another)");
  cmd.add_option("--target-crs", target_crs,
                 "Reproject the points into this CRS (given as for --assign-crs) before voxelising; " + grid_flags +
                     " are then in its units");
  cmd.add_flag("--allow-geographic", allow_geographic,
               "Voxelise in a geographic CRS anyway (voxels of degrees by units of height, not cubes; "
               "refused without it: give --target-crs)");
  cmd.add_option("--crs", assign_crs, "Old name of --assign-crs")
      ->group("")  // hidden: the help teaches the two clear names
      ->each([](const std::string&) {
        std::fprintf(stderr, "vola: --crs is now --assign-crs (it relabels; --target-crs moves the points)\n");
      });
}

std::string crs_summary_line(const std::optional<std::uint32_t>& epsg, const std::string& wkt) {
  if (wkt.empty() && !epsg) return "";
  try {
    return geo::crs_summary(geo::describe_crs(!wkt.empty() ? wkt : "EPSG:" + std::to_string(*epsg)));
  } catch (const Error&) {
    return "";
  }
}

}  // namespace vola::cli
