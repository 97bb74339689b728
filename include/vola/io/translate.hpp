// vola translate: point files to point files, point by point, no voxels (PDAL's translate).
#pragma once

#include <cstdint>
#include <functional>
#include <string>

namespace vola::io {

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
void translate_points(const std::string& input, const std::string& output,
                      const std::function<void(std::uint64_t, std::uint64_t)>& progress = {});

}  // namespace vola::io
