// vola translate: point files to point files, point by point, no voxels (PDAL's translate).
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "vola/builder.hpp"
#include "vola/io/las.hpp"

namespace vola::io {

// Every point of a point file with every field it has as a named column (Reduction::last
// for LAS fields), in file order, and the CRS the file states.
struct PointTable {
  std::string format;  // the reader's name
  PointCloud cloud;
  std::optional<std::uint32_t> epsg;
  std::string wkt;
  int coordinate_digits = -1;  // LAS: decimals of the finest scale; -1 elsewhere
  std::uint64_t not_finite = 0;  // points the reader left out (io::Input::not_finite)
  // LAS: how many of cloud's columns, first, are fields of the point record; the rest are
  // extra bytes (which may be named like a field this point format does not have).
  std::size_t record_fields = 0;
};
// LAS/LAZ/COPC input gives intensity, return_number, number_of_returns, classification,
// user_data, point_source_id, gps_time, red/green/blue and extra bytes by name; other
// point files what their reader keeps. Throws InvalidArgument for a mesh, grid or DEM.
// `format`: "auto" (from the extension) or a name from input_formats().
PointTable read_point_table(const std::string& input, const std::function<void(std::uint64_t, std::uint64_t)>& progress = {},
                            const std::string& format = "auto");

// The dimensions of a LAS/LAZ/COPC file's point records beyond x y z: the columns
// read_point_table gives for it, empty.
PointCloud las_columns(const LasHeader& header);
// The records `reader` has not read yet, 65,536 at a time, as x y z and las_columns'
// columns: each chunk is handed to `each` and then reused, so that memory stays a chunk's
// whatever the file's size (vola info --summary).
void for_each_las_chunk(LasReader& reader, const std::function<void(const PointCloud&)>& each,
                        const std::function<void(std::uint64_t, std::uint64_t)>& progress = {});
// What happens to the points between reading and writing (point filters): may change
// columns, add some and drop points; returns, for each point left, its index in the input.
using PointEdit = std::function<std::vector<std::uint64_t>(PointTable&)>;

// `input` (any point format vola reads: LAS, LAZ, COPC, PLY, PCD, XYZ/TXT/CSV, NPY,
// KITTI) into `output`, by its extension:
//   .las, .laz  record for record from LAS/LAZ/COPC input (translate_las in las.hpp);
//               other input as LAS 1.4 format 6/7 points (io::write_las of a cloud);
//   .ply        binary PLY: x y z as double, then every column in its own type;
//   .xyz, .txt  text, "# x y z names..." then one point a line (LAS input: coordinates
//               at the file's precision).
// LAS/LAZ/COPC input gives every field of its records as columns: intensity,
// return_number, number_of_returns, classification, user_data, point_source_id,
// gps_time, red/green/blue, and extra bytes by name. Points keep their input order; the
// output is written under a temporary name and renamed when complete. Throws
// InvalidArgument for an output kind it does not write, FormatError for bad input.
// With `edit`, the points are read whole, edited, then written: LAS/LAZ to LAS/LAZ keeps
// the records of the points left, byte for byte but their classification (taken from the
// column) and the header's counts and bounds; columns the record has no field for (a
// new one such as height_above_ground) go to PLY and XYZ outputs only.
// Returns warnings for the user: what the output cannot hold (a PLY or XYZ file has no
// place for the input's CRS). `format`: the input's reader, "auto" (from the extension) or
// a name from input_formats().
std::vector<std::string> translate_points(const std::string& input, const std::string& output,
                                          const std::function<void(std::uint64_t, std::uint64_t)>& progress = {},
                                          const PointEdit& edit = {}, const std::string& format = "auto");

}  // namespace vola::io
