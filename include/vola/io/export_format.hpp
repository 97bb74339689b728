// Which format an export writes, from its output's extension and the options given: the
// one rule `vola export` and Python's vola.export share. Options are named as the
// members below (`vola export` shows them as --flags, Python as keywords).
#pragma once

#include <string>

namespace vola::io {

struct ExportRequest {
  std::string output;             // the file to write (a folder for slices)
  std::string format = "auto";    // auto (from the extension), or one of the formats below
  bool slices = false;            // PNG slices into a folder
  bool map = false;               // a PNG height map
  bool occupancy_above = false;   // a PNG of the columns occupied above a height
  bool raster = false;            // a GeoTIFF product was named
  bool resolution = false;        // a raster resolution was given
  bool ascii = false, cubes = false;  // PLY options
  bool bits = false;              // a height-map bit depth other than 16
  bool free = false;              // a tree of free voxels (maps)
  bool band = false;              // a height band (ROS maps)
};

// "ply", "xyz", "las" (.las and .laz), "binvox", "npy", "png" (slices, map or
// occupancy_above), "tif", "octomap" (.bt, .ot), "vdb" or "rosmap" (.yaml, .yml: a ROS
// map_server map, which needs `band`), after checking that every option
// given applies to it. OptionError (its cause naming options as `member`) otherwise.
std::string resolve_export_format(const ExportRequest& request);

}  // namespace vola::io
