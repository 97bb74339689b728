// Occupancy maps in the robotics formats: OctoMap's .bt (binary, maximum likelihood) and
// .ot (with probabilities) through liboctomap, OpenVDB's .vdb through OpenVDB. Both
// libraries run in plugins, libvola_octomap.so and libvola_openvdb.so (src/plugin/plugin.hpp
// says why), loaded by the first call that needs one.
//
// Writing takes a MapVoxels: occupied voxels and, optionally, free ones, each with or
// without log-odds, on one grid. map_voxels() makes it from trees (the occupied tree and
// the free tree `vola map --free` writes); a map held another way (a state map with a bit
// per known voxel) fills the struct directly.
//
// Reading gives a VoxelGrid (vola/io/input.hpp) of the occupied cells at the file's own
// voxel size, which `vola convert` maps cell for cell; readers are in the format table
// (io::input_formats(): "octomap" for .bt/.ot, "vdb" for .vdb).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "vola/frame.hpp"
#include "vola/io/input.hpp"
#include "vola/tree.hpp"

namespace vola::io {

// The known voxels of an occupancy map, in two states, on one grid.
struct MapVoxels {
  // Grid quantization: voxel (i, j, k) covers origin + [i, i + 1) * voxel_size per axis.
  Frame frame{Quantization::grid, {0, 0, 0}, 1.0};
  std::vector<Voxel> occupied;
  // One log-odds per occupied voxel, or empty: every occupied voxel at OctoMap's clamping
  // maximum (probability 0.971).
  std::vector<float> occupied_log_odds;
  std::vector<Voxel> free;
  // One log-odds per free voxel, or empty: OctoMap's clamping minimum (0.1192).
  std::vector<float> free_log_odds;

  // Throws InvalidArgument when a log-odds list is neither empty nor one per voxel, a
  // log-odds is not finite, a voxel lies beyond a depth-10 grid (2^20 per axis), or the
  // voxel size is not finite and > 0, or a voxel is both occupied and free.
  void check() const;
};

// The voxels of `occupied` and, when given, of `free`, with the log-odds of their
// "log_odds" columns when they have one (`vola map` writes it). The frame is the
// occupied tree's (its recorded grid, or the toolkit grid of its header bbox); a free
// tree must have the same voxel size and an origin a whole number of voxels away
// (InvalidArgument otherwise): the frame's origin is then the lower of the two per axis.
MapVoxels map_voxels(const Tree& occupied, const Tree* free = nullptr);

struct MapExportReport {
  std::uint64_t occupied = 0, free = 0;  // voxels written
  bool log_odds = false;                 // probabilities from the log-odds given (else clamping values)
  // OctoMap: what was added to every world coordinate so that the voxels fall on OctoMap's
  // cells (zero when the grid already lines up with them; see write_octomap).
  Point shift{0, 0, 0};
  std::uint64_t nodes = 0;         // OctoMap: nodes of the pruned tree
  std::vector<std::string> grids;  // OpenVDB: the grids written, in file order
  // What a careful user should know (the map moved), one sentence each.
  std::vector<std::string> warnings;
};

// OctoMap keeps 2^16 cells per axis, keys 0..65535, cell key k covering
// [(k - 32768) R, (k - 32767) R) for resolution R = the voxel size.
inline constexpr std::int64_t kOctomapKeyCentre = 32768;

// An OctoMap OcTree at resolution R = frame.voxel_size, written as `.bt`
// (writeBinary: maximum likelihood, occupied and free leaves) or `.ot` (write: every
// leaf's log-odds, clamped to OctoMap's defaults), chosen by the extension of `path`. Each
// voxel goes to the cell OctoMap's coordToKey gives its centre; the tree is pruned.
// Where the cells lie:
//  - origin a multiple of R and every voxel within OctoMap's keys: the voxels' own world
//    cells, no shift (maps written by `vola map` always are);
//  - origin not a multiple of R: the map moves by less than half a voxel per axis, onto the
//    nearest cells (shift in the report, a warning);
//  - voxels beyond OctoMap's keys (georeferenced surveys: UTM or state-plane coordinates
//    are millions of voxels from 0): the map moves by -origin, so that the grid's corner
//    is OctoMap's 0 (shift in the report, a warning); voxels 32768 or more from the
//    grid's corner are then refused (InvalidArgument: crop or coarsen first).
// A voxel both occupied and free is refused; so is a tree above kMaxMapLibraryBytes.
MapExportReport write_octomap(const MapVoxels& voxels, const std::string& path);

// An OpenVDB file of grids in the map's frame: the first "occupied" (BoolGrid, the
// occupied voxels active and true) or, with occupied log-odds, "log_odds" (FloatGrid);
// with free voxels a second, "free" (BoolGrid) or "free_log_odds" (FloatGrid). Each grid's
// transform is a uniform scale by the voxel size and a translation that puts index
// (i, j, k)'s voxel centre (OpenVDB's convention: centres at integer indices) on the
// world centre of vola voxel (i - n_x, j - n_y, k - n_z), n = round(origin / R): grids of
// one voxel size share an index space whatever their origins. Trees pruned, Blosc or zip
// compression as OpenVDB defaults. Grids above kMaxMapLibraryBytes are refused.
MapExportReport write_vdb(const MapVoxels& voxels, const std::string& path);

// The library's own tree for a map is refused above this many bytes, estimated from its
// node sizes and the voxels' node counts before it is built (InvalidArgument naming the
// estimate): OpenVDB's internal nodes take 33 KiB and 264 KiB each, so voxels scattered
// thinly over a wide grid cost far more there than in vola (10^6 uniform voxels at depth
// 10: about 40 GB). 4 GiB.
inline constexpr std::uint64_t kMaxMapLibraryBytes = std::uint64_t{4} << 30;

// Readers, as the format table calls them. Maps are refused above this many occupied
// voxels once pruned nodes are expanded (a lying header or a solid octant of a huge map):
// 2^28 voxels, ~8 GiB for the conversion's keys, attributes and sorting.
inline constexpr std::uint64_t kMaxMapVoxels = std::uint64_t{1} << 28;

// OctoMap .bt/.ot: the occupied leaves (log-odds at or above 0, OctoMap's default
// threshold 0.5), pruned nodes expanded to cells of the file's resolution; origin =
// (lowest key - 32768) * R per axis, so voxel (i, j, k) is OctoMap's key (i, j, k) + the
// lowest key. `.ot` (with options.attributes): the leaves' log-odds as column
// "log_odds" (f32). The file's structure is checked before liboctomap parses it.
VoxelGrid read_octomap(const std::string& path, const InputOptions& options);
// OpenVDB .vdb: the active voxels (tiles expanded) of the grid named options.grid, or of
// the file's first grid when that is empty; float, double and 32-bit integer grids' values as a column named
// after the grid (with options.attributes). The transform must be a uniform scale and a
// translation (rotated, sheared, non-uniform or frustum transforms are refused).
VoxelGrid read_vdb(const std::string& path, const InputOptions& options);

}  // namespace vola::io
