#include "crs_flags.hpp"

#include <cstdio>

namespace vola::cli {

void add_crs_options(CLI::App& cmd, std::string& assign_crs, std::string& target_crs, bool& allow_geographic) {
  cmd.add_option("--assign-crs", assign_crs,
                 "The inputs' CRS (EPSG code, WKT or PROJ string), relabelling them without moving a point "
                 "(default: what the inputs say; a warning when they say another)");
  cmd.add_option("--target-crs", target_crs,
                 "Reproject the points into this CRS (EPSG code, WKT or PROJ string) before voxelising; "
                 "--voxel-size, --origin and --bbox are then in its units");
  cmd.add_flag("--allow-geographic", allow_geographic,
               "Voxelise in a geographic CRS anyway (voxels of degrees by units of height, not cubes; "
               "refused without it: give --target-crs)");
  cmd.add_option("--crs", assign_crs, "Old name of --assign-crs")
      ->group("")  // hidden: the help teaches the two clear names
      ->each([](const std::string&) {
        std::fprintf(stderr, "vola: --crs is now --assign-crs (it relabels; --target-crs moves the points)\n");
      });
}

}  // namespace vola::cli
