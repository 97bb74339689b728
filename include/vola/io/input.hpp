// One entry point for every input format: `read_input` picks the reader by format
// name or file extension and returns points, voxels or triangles, plus the CRS the
// input states. `vola convert` turns any of them into a tree.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "vola/builder.hpp"
#include "vola/io/text_points.hpp"

namespace vola::io {

struct InputOptions {
  bool attributes = true;  // keep per-point attributes the format carries
  bool payload = false;    // build the reference's payload word per point where the format defines one
  TextColumns text;        // text formats: which columns are what
  // Formats that can stream (LAS) leave Input::cloud empty and set Input::build, which
  // reads the file in chunks into a vola::StreamBuilder: memory ~ voxels, not points.
  bool stream = false;
  std::function<void(std::uint64_t, std::uint64_t)> progress;  // (done, total), any unit
  std::optional<double> dem_base;  // DEM: height the columns start from (default: the lowest cell)
  bool dem_surface_only = false;   // DEM: one voxel per cell, no column below it
  double map_height = 0.0;         // ROS maps: occupied cells' column height (0: one voxel)
  std::optional<int> copc_level;   // COPC and EPT: only the octree's levels 0..copc_level
  // EPT: nodes whose cube misses this box are not read (vola convert passes the grid's
  // region, vola::grid_region, when a bbox fixes the grid); points outside it may still
  // come back from the nodes that are read.
  std::optional<Box> region;
  std::string grid;                // OpenVDB: the grid to read (empty: the only one, or vola's own occupied grid);
                                   // .npz: the array to read (empty: npz_points_member's choice)
};

// Occupied cells of an input that is already a voxel grid (binvox, NPY occupancy).
struct VoxelGrid {
  std::array<std::uint32_t, 3> dims{0, 0, 0};  // cells per axis
  Point origin{0, 0, 0};                       // world position of cell (0,0,0)'s corner
  double voxel_size = 1.0;                     // world size of one cell
  std::vector<Voxel> voxels;                   // occupied cells, any order
  // Per-cell values (one per voxel, in the order of `voxels`), kept as attribute columns.
  std::vector<PointAttribute> attributes;
  // Maps (OctoMap, OpenVDB): the cells are the map's own; a conversion to another voxel
  // size is refused rather than resampled.
  bool fixed_voxel_size = false;
  // A map's free cells (OctoMap's free leaves, in the grid's coordinates), with their
  // log-odds when the file has them (an .ot): a conversion makes a state map of them and
  // the occupied cells, whose log-odds are then the "log_odds" column (empty: OctoMap's
  // clamping values, as a .bt's leaves hold).
  std::vector<Voxel> free;
  std::vector<float> free_log_odds;
  // Free cells the reader did not keep (occupancy only asked for, a ColorOcTree, or more
  // than kMaxMapVoxels of them): a conversion says so, since the .vol then reads them as
  // free only by default, and unknown space alike.
  std::uint64_t free_cells_dropped = 0;
};

using Triangle = std::array<Point, 3>;

struct Input {
  std::string format;                  // the reader that produced it
  PointCloud cloud;                    // point formats
  std::optional<VoxelGrid> grid;       // voxel formats
  std::vector<Triangle> triangles;     // mesh formats
  // Set by streaming readers (InputOptions::stream): builds the tree from the file,
  // resolving the options like vola::build.
  std::function<Tree(const BuildOptions&, BuildReport*)> build;
  std::optional<std::uint32_t> epsg;   // what the input says its CRS is
  std::string wkt;
  // The points' box as the file's header states it (LAS), for what is said before a
  // streamed read (a CRS label its coordinates cannot fit); not trusted for building.
  std::optional<Box> stated_bounds;
  // Points the reader left out for a coordinate that is not finite (a PCD organized
  // cloud's missing points), so that counts of the file's points stay true.
  std::uint64_t not_finite = 0;
  // Readers that can skip parts of a file (COPC, EPT) say how many bytes they read so far,
  // and, when the input is more than the file named (EPT: its node files), the bytes of
  // the whole input (0: the named file's size).
  std::function<std::uint64_t()> bytes_read;
  std::uint64_t bytes_total = 0;
  // Height fields (DEM): `cloud` holds one point per cell centre at the cell's height,
  // each to become a column of voxels down (or up) to terrain_base, or only the voxel
  // of its height when terrain_surface_only.
  bool terrain = false;
  double terrain_base = 0.0;
  bool terrain_surface_only = false;
  // A corner of the raster's cells (north-up rasters): the default grid origin lines up
  // with the cells rather than with multiples of the voxel size.
  std::optional<std::array<double, 2>> terrain_lattice;
  // The cells' width and height (north-up rasters): a cell covers every voxel column whose
  // centre lies on it, not only the one under its centre.
  std::optional<std::array<double, 2>> terrain_cell;
  bool is_mesh() const noexcept { return !triangles.empty(); }
};

struct InputFormat {
  std::string name;
  std::vector<std::string> extensions;  // lower case, with the dot
  std::string description;
  std::function<Input(const std::string& path, const InputOptions&)> read;
};

// Every format this build reads.
const std::vector<InputFormat>& input_formats();
// The file name's extension, lower case, with its dot (".laz"; "" when it has none): what
// readers and writers choose a format by.
std::string lower_extension(const std::string& path);
// The format for `path` ("auto" looks at the extension); throws InvalidArgument
// listing what is known otherwise.
const InputFormat& find_input_format(const std::string& path, const std::string& name = "auto");
Input read_input(const std::string& path, const std::string& format, const InputOptions& options);

}  // namespace vola::io
