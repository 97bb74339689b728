// The one road from an input file to a tree: reader -> points, voxels or triangles ->
// builder -> tree (-> writer). `vola convert`, Python's vola.convert and the C API's
// vola_convert are thin shells over these two calls; every option and every rule about
// quantization, bounding boxes, CRSs and attributes is decided here, once.
//
//   vola::ConvertOptions options;
//   options.voxel_size = 2.0;                                   // grid mode, input units
//   vola::convert_file("survey.las", "survey.vol", options);    // streams: memory ~ voxels
//
// Errors: OptionError naming the ConvertOptions member that is wrong (so that each front
// end can name its own spelling of it), FormatError naming the file and byte offset.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "vola/builder.hpp"
#include "vola/file.hpp"
#include "vola/filters/stages.hpp"
#include "vola/tree.hpp"

namespace vola {

struct ConvertOptions {
  // The reader: "auto" (from the file's extension) or a name from io::input_formats().
  std::string format = "auto";

  // ---- the grid (BuildOptions::check() holds the rules) ----
  // Unset: grid when voxel_size or origin is given, else toolkit.
  std::optional<Quantization> quantization;
  int depth = 0;            // 1..10; grid mode: 0 = the smallest that covers the input
  double voxel_size = 0.0;  // grid mode: the voxel edge in input units
  std::optional<Point> origin;  // grid mode: world position of voxel (0,0,0)'s corner
  std::optional<Box> bbox;      // quantize against this box instead of the input's bounds
  int nbits = 0;                // payload words per block: 0 occupancy only, 1 the reference's

  // ---- what the input is ----
  // The input's CRS, relabelled: any definition PROJ reads ("EPSG:2994", "2994", WKT, a
  // PROJ string). It wins over what the input says, without moving a point (a warning
  // says so when the input states another CRS); to move the points, give target_crs.
  std::string assign_crs;
  // The same as an EPSG code (the Python and C front ends' `epsg`); not with assign_crs.
  std::optional<std::uint32_t> epsg;
  // Reproject the points into this CRS before voxelising ("EPSG:32610", "32610", WKT or
  // a PROJ string); the grid options (voxel_size, origin, bbox) are then in its units.
  // Point input only; the input's CRS (stated, or `epsg`) is the source. The points are
  // read whole for it (not streamed).
  std::string target_crs;
  // Grid voxels in a geographic CRS (degrees of longitude and latitude by metres of
  // height, not cubes) are refused unless forced here or target_crs reprojects them.
  bool allow_geographic = false;
  // COPC and EPT input: read only the octree's levels 0..level (0 = the root's points), a
  // coarser sample of the cloud from a small part of the file. With a grid bbox, nodes
  // outside the grid are skipped whatever the level (EPT: unless filters or target_crs
  // are given, since filters look around the window and reprojection moves the points).
  std::optional<int> level;
  // OpenVDB input: the grid to read (empty: the file's first); NumPy .npz input: the array
  // to read (empty: the only one, or the one named points, xyz, ...: io::npz_points_member).
  // Maps (OctoMap, OpenVDB) keep their own cells: a voxel_size other than the file's is refused.
  std::string grid;
  bool attributes = true;  // keep the per-point attributes the format carries (LAS, PLY, PCD, ...)
  // Text input (XYZ/TXT/CSV); column numbers count from 1, as a user reads the file.
  // x y z columns (1-based); none given: found by name in a header line, else 1 2 3. Given
  // (1 2 3 too), they win over the header's names.
  std::optional<std::array<int, 3>> columns;
  std::vector<int> payload_columns;     // nbits 1: payload bytes 0..7 (default: every column after x y z)
  // Columns kept as attributes: NAME=COLUMN[:TYPE[:REDUCTION]], e.g. "intensity=4:u16:mean";
  // TYPE u8..u64 i8..i64 f32 f64 (default f32), REDUCTION last mean max min majority (default:
  // io::default_reduction of NAME, as for a header's columns).
  std::vector<std::string> text_attributes;
  int skip_lines = 0;               // header lines before the points
  bool solid = false;               // meshes: fill the inside of closed surfaces too
  std::optional<double> dem_base;   // DEM: height the columns start from (default: the lowest cell)
  bool dem_surface_only = false;    // DEM: one voxel per cell at its height
  double map_height = 0.0;          // ROS maps (.yaml): occupied cells as columns this high (0: one voxel)

  // ---- point filters, run in order on the points before they become voxels ----
  // One string per stage, as include/vola/filters/stages.hpp writes them: "where:EXPR",
  // "smrf", "hag", "outlier", "voxel:R", "poisson:R", "crop:MINX,MINY,MAXX,MAXY",
  // "polygon:FILE". Point input only. Filters that need every point (smrf, hag,
  // outlier, voxel, poisson) read the input whole; per-point ones (where, crop,
  // polygon) alone leave LAS/LAZ streaming, chunk by chunk.
  std::vector<std::string> filters;

  // ---- the file convert_file writes ----
  bool dense = false;     // the reference's dense layout (depth <= 5)
  bool compress = false;  // zstd levels and attributes (a file only vola reads)
  // compress, with the occupancy coded by mixed context models (WriteOptions::
  // mix_occupancy_models): the smallest files, several times slower to open.
  bool compress_max = false;

  // Every rule above that needs no input; the rest (e.g. solid on a point file) is
  // checked once the reader has said what the input is. Throws OptionError.
  void check() const;
};

struct ConvertReport {
  BuildReport build;             // points (or triangles, cells) in and dropped, voxels out
  std::string unit = "points";   // what build.points_in counts: points, triangles or cells
  std::string format;            // the reader that read the input
  // The CRS: its EPSG code when known (given, stated, or found from the input's WKT);
  // crs_wkt_only when the input gave a WKT with no code for it.
  std::optional<std::uint32_t> epsg;
  bool crs_wkt_only = false;
  // Bytes of the input read, when the reader counts them (LAS, LAZ, COPC, EPT): with
  // --level or a grid bbox, less than the input's bytes_total (an EPT dataset's node
  // files; otherwise the file's size, left empty).
  std::optional<std::uint64_t> bytes_read;
  std::optional<std::uint64_t> bytes_total;
  // What a careful user should know about the result (a CRS relabelled, voxels in
  // degrees allowed or quantized by the toolkit): one sentence each, for the front end.
  std::vector<std::string> warnings;
  // Points each filter stage took in and left ("smrf: 110000 -> 110000, 26411 ground"),
  // as lines and as counts.
  std::vector<std::string> filters;
  std::vector<filters::StageReport> filter_stages;
};

// (done, total) in any unit, now and then during long reads.
using ConvertProgress = std::function<void(std::uint64_t done, std::uint64_t total)>;

// Reads `input` and builds its tree: voxel grids cell for cell unless another grid is
// asked for, meshes voxelized (solid on request), DEM cells as columns, points quantized;
// formats that can stream (LAS) are read in chunks, so memory follows voxels, not points.
Tree convert(const std::string& input, const ConvertOptions& options, const ConvertProgress& progress = {},
             ConvertReport* report = nullptr);

// How convert_file writes: the options' dense, compress and compress_max (every front end
// that writes a converted tree itself takes its WriteOptions from here).
WriteOptions write_options_of(const ConvertOptions& options);

// Throws InvalidArgument when `output` is the input itself, or a name with another
// format's extension (`a.las`: the bytes would be a .vol named .las).
void check_convert_output(const std::string& input, const std::string& output);

// check_convert_output, convert(), then write the tree to `output` as the options say
// (dense, compress).
void convert_file(const std::string& input, const std::string& output, const ConvertOptions& options,
                  const ConvertProgress& progress = {}, ConvertReport* report = nullptr);

}  // namespace vola
