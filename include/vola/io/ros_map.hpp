// ROS 2D occupancy grids (map_server / nav2_map_server: a YAML file and its PGM image, as
// map_saver writes them): written from a 3D map, the voxels whose centres lie in a height
// band (the space a robot sweeps) projected onto the floor plan; read as voxel columns.
#pragma once

#include <array>
#include <cstdint>
#include <string>

#include "vola/io/input.hpp"
#include "vola/io/occupancy_maps.hpp"

namespace vola::io {

struct RosMapOptions {
  double z_min = 0.0, z_max = 0.0;  // the band, in the file's units: voxel centres z_min <= z <= z_max
};

struct RosMapReport {
  std::string image;  // the PGM's path, beside the YAML
  std::uint32_t width = 0, height = 0;
  double resolution = 0.0;                            // cell edge: the voxel size
  std::array<double, 2> origin{};                     // the lower-left corner of the image, as the YAML says
  std::uint64_t occupied = 0, free = 0, unknown = 0;  // cells
  bool free_from_ground = false;  // free cells are columns with data below the band (no free voxels given)
};

// Writes `yaml_path` and the PGM beside it (same name, .pgm) from a map's voxels (as
// map_voxels gathers them: a state map's occupied and free voxels, or a plain tree with
// or without a tree of free ones). Each cell is one voxel column, cropped to the columns
// that hold a voxel (occupied or free) at any height:
//  - occupied (0, black) when an occupied voxel's centre lies in the band;
//  - free (254, white) when a free voxel's centre lies in the band; when the map has no
//    free voxels at all, when the column holds an occupied voxel below the band (ground
//    seen, nothing in the way);
//  - unknown (205) otherwise.
// Pixel values and thresholds are map_saver's (trinary mode, negate 0, occupied_thresh
// 0.65, free_thresh 0.196). OptionError ("band") for a band that is not finite, upside
// down or holds no voxel layer of the map; InvalidArgument for an empty map or more than
// 2^28 cells (what read_ros_map takes).
RosMapReport write_ros_map(const MapVoxels& voxels, const std::string& yaml_path, const RosMapOptions& options);

// A map_server map (its YAML, naming a PGM or PNG image beside it or by an absolute path) as voxel
// columns: every occupied cell (map_server's rule: p = (255 - v) / 255, v / 255 when
// negated, occupied when p > occupied_thresh; raw mode: v percent) becomes a column of
// ceil(height / resolution) voxels (one when height is 0) from z = 0, on the map's grid
// (voxel size = resolution, origin = the YAML's origin x, y and 0). Free and unknown cells
// are left out. FormatError (file, byte) for a YAML that is not flat keys, a missing key,
// a yaw other than 0, a truncated or lying PGM; OptionError ("map_height") for a height
// that is negative or makes more than 2^28 voxels.
VoxelGrid read_ros_map(const std::string& yaml_path, double height);

}  // namespace vola::io
