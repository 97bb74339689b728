// vola export: a .vol file back out as PLY, XYZ, LAS, binvox, a dense NPY grid, PNG
// images, GeoTIFF rasters or occupancy maps (OctoMap, OpenVDB).
#include <algorithm>
#include <cctype>
#include <cstdio>
#include <filesystem>
#include <string>

#include "commands.hpp"
#include "number_checks.hpp"
#include "open_voxels.hpp"
#include "vola/error.hpp"
#include "vola/file.hpp"
#include "vola/geo/crs.hpp"
#include "vola/io/binvox.hpp"
#include "vola/io/export.hpp"
#include "vola/io/export_format.hpp"
#include "vola/io/file_checks.hpp"
#include "vola/io/input.hpp"
#include "vola/io/occupancy_maps.hpp"
#include "vola/io/ros_map.hpp"
#include "vola/map/state_map.hpp"

namespace vola::cli {

namespace {

struct ExportArgs {
  std::string input, output, format = "auto";
  bool ascii = false, cubes = false, slices = false, map = false, quiet = false;
  int depth = 0;
  int bits = 16;
  std::uint32_t above = 0;
  bool above_given = false;
  std::string raster;       // dsm, dtm, ... (empty: no raster)
  double resolution = 0.0;  // 0: the voxel size
  bool resolution_given = false;
  std::string free;  // maps: a .vol of the free voxels (`vola map --free`)
  std::string band;  // ROS maps: ZMIN:ZMAX
};

// The format, after checking that the options given apply to it (the rule Python's
// vola.export shares).
std::string resolve_format(const ExportArgs& a) {
  io::ExportRequest request;
  request.output = a.output;
  request.format = a.format;
  request.slices = a.slices;
  request.map = a.map;
  request.occupancy_above = a.above_given;
  request.raster = !a.raster.empty();
  request.resolution = a.resolution_given;
  request.ascii = a.ascii;
  request.cubes = a.cubes;
  request.bits = a.bits != 16;
  request.free = !a.free.empty();
  request.band = !a.band.empty();
  return io::resolve_export_format(request);
}

// The free voxels: a state map's own (vola map), else --free's plain tree, else none; at a
// coarser --depth beside the occupied voxels at that depth (map::free_at_depth).
std::optional<Tree> free_voxels(const ExportArgs& a, const Tree& occupied) {
  std::optional<Tree> free;
  const Tree input = open_mapped(a.input);
  if (map::is_state_map(input)) {
    if (!a.free.empty())
      throw InvalidArgument(a.input + " is a state map and holds its free voxels; --free is for plain trees");
    free = map::free_tree(input);
  } else if (!a.free.empty()) {
    free = open_mapped(a.free);
  }
  if (free) free = map::free_at_depth(*free, occupied, a.depth);
  return free;
}

void export_map(const ExportArgs& a, const Tree& tree, const std::string& format) {
  const std::optional<Tree> free = free_voxels(a, tree);
  const io::MapVoxels voxels = io::map_voxels(tree, free ? &*free : nullptr);
  const io::MapExportReport r = format == "vdb" ? io::write_vdb(voxels, a.output) : io::write_octomap(voxels, a.output);
  for (const auto& warning : r.warnings) std::fprintf(stderr, "vola: warning: %s\n", warning.c_str());  // even with -q
  if (a.quiet) return;
  const std::string probabilities = r.log_odds ? "log-odds from the log_odds columns" : "occupancy only";
  std::string what;
  if (format == "vdb") {
    what = "OpenVDB grids";
    for (const auto& name : r.grids) what += " " + name;
  } else {
    const bool binary = io::lower_extension(a.output) == ".bt";
    what = std::string("OctoMap OcTree ") + (binary ? "(.bt, maximum likelihood)" : "(.ot, " + probabilities + ")") +
           " of " + std::to_string(r.nodes) + " nodes";
  }
  std::printf("%s: %llu occupied and %llu free voxels of %.17g -> %s\n", what.c_str(),
              static_cast<unsigned long long>(r.occupied), static_cast<unsigned long long>(r.free),
              voxels.frame.voxel_size, a.output.c_str());
}

// --band ZMIN:ZMAX as two numbers.
io::RosMapOptions band_heights(const std::string& band) {
  const std::size_t colon = band.find(':', 1);  // past a leading minus sign
  io::RosMapOptions options;
  std::size_t used_min = 0, used_max = 0;
  try {
    if (colon == std::string::npos) throw std::invalid_argument("no colon");
    options.z_min = std::stod(band.substr(0, colon), &used_min);
    options.z_max = std::stod(band.substr(colon + 1), &used_max);
  } catch (const std::exception&) {
    used_min = 0;
  }
  if (colon == std::string::npos || used_min != colon || used_max != band.size() - colon - 1)
    throw OptionError("band", "is ZMIN:ZMAX, two heights in the file's units (e.g. 0.2:1.8), not '" + band + "'");
  return options;
}

void export_ros_map(const ExportArgs& a, const Tree& tree) {
  const std::optional<Tree> free = free_voxels(a, tree);
  const io::MapVoxels voxels = io::map_voxels(tree, free ? &*free : nullptr);
  const io::RosMapReport r = io::write_ros_map(voxels, a.output, band_heights(a.band));
  if (a.quiet) return;
  std::printf(
      "ROS map (map_server YAML + PGM, trinary): %u x %u cells of %.17g, origin (%.17g, %.17g): %llu occupied, "
      "%llu free (%s), %llu unknown -> %s, %s\n",
      r.width, r.height, r.resolution, r.origin[0], r.origin[1], static_cast<unsigned long long>(r.occupied),
      static_cast<unsigned long long>(r.free),
      r.free_from_ground ? "columns with voxels below the band and none in it" : "free voxels in the band",
      static_cast<unsigned long long>(r.unknown), a.output.c_str(), r.image.c_str());
}

// Only LAS/LAZ and GeoTIFF carry a CRS; PLY, XYZ, binvox, NPY, PNG with its world file,
// OctoMap and OpenVDB files lose it. Said, as vola translate says it, even with -q.
void warn_if_crs_is_lost(const ExportArgs& a, const Tree& tree, const std::string& format) {
  if (format == "las" || format == "tif") return;  // they keep it
  const std::optional<std::string> crs = geo::crs_definition(tree.georef());
  if (!crs) return;
  const std::string named = tree.georef().crs_wkt.empty() ? *crs : "a WKT";
  std::fprintf(stderr,
               "vola: warning: %s: this format has no place for the CRS of %s (%s): it is not kept; a .las/.laz or "
               "GeoTIFF (--raster) export keeps it\n",
               a.output.c_str(), a.input.c_str(), named.c_str());
}

void run_export(const ExportArgs& a) {
  io::refuse_output_over_input(a.input, a.output, "vola export writes another file; give it another name");
  if (!a.free.empty()) io::refuse_output_over_input(a.free, a.output, "it is --free's file; give the output another name");
  const std::string format = resolve_format(a);
  Tree tree = open_voxels(a.input);
  if (a.depth > tree.depth())
    throw InvalidArgument("--depth " + std::to_string(a.depth) + " is deeper than the file's depth " +
                          std::to_string(tree.depth()));
  if (a.depth > 0 && a.depth < tree.depth()) {
    // A coarser grid carries no attribute columns: say so rather than "no intensity column".
    if (a.raster == "intensity" && tree.attributes().find("intensity"))
      throw InvalidArgument("--raster intensity needs the intensity column, which --depth " + std::to_string(a.depth) +
                            " drops (a coarser grid carries no attribute columns); for coarser cells give "
                            "--resolution R at the file's depth instead");
    tree = tree.level_of_detail(a.depth);
  }
  const unsigned long long voxels = tree.voxel_count();
  auto say = [&](const std::string& what) {
    if (!a.quiet) std::printf("%s -> %s\n", what.c_str(), a.output.c_str());
  };

  if (format == "ply") {
    io::PlyOptions options;
    options.ascii = a.ascii;
    options.cubes = a.cubes;
    const io::PlyReport r = write_ply(tree, a.output, options);
    say("PLY (" + std::string(a.ascii ? "ascii" : "binary") + "): " + std::to_string(r.vertices) + " vertices" +
        (a.cubes ? ", " + std::to_string(r.faces) + " faces (outer surface of " + std::to_string(voxels) + " voxels)"
                 : ""));
  } else if (format == "xyz") {
    io::write_xyz(tree, a.output);
    say("XYZ: " + std::to_string(voxels) + " voxel centres");
  } else if (format == "csv") {
    io::write_csv(tree, a.output);
    say("CSV: " + std::to_string(voxels) + " voxel centres");
  } else if (format == "las") {
    const io::LasReport r = io::write_las(tree, a.output);
    std::string what = std::string(io::lower_extension(a.output) == ".laz" ? "LAZ" : "LAS") + " 1.4 point format " +
                       std::to_string(r.point_format) + ": " + std::to_string(voxels) +
                       " points, CRS ";
    if (r.has_crs) what += "as WKT";
    else if (geo::crs_definition(tree.georef())) what += "none (PROJ does not know EPSG:" + std::to_string(tree.georef().epsg) + ")";
    else what += "none (the file has no CRS)";
    if (!r.extra_bytes.empty()) {
      what += ", extra bytes:";
      for (const auto& name : r.extra_bytes) what += " " + name;
    }
    say(what);
    for (const std::string& unfit : r.unfit_values)  // a warning, even with -q: values were changed
      std::fprintf(stderr, "vola: warning: %s: %s\n", a.output.c_str(), unfit.c_str());
  } else if (format == "binvox") {
    io::write_binvox(tree, a.output);
    say("binvox: " + std::to_string(voxels) + " voxels");
  } else if (format == "npy") {
    io::write_npy_grid(tree, a.output);
    say("NPY uint8 grid of " + std::to_string(tree.side()) + "^3 cells, " + std::to_string(voxels) + " occupied");
  } else if (format == "tif") {
    io::RasterOptions options;
    options.product = *io::raster_product(a.raster);
    options.resolution = a.resolution;
    const io::RasterReport r = io::write_geotiff(tree, a.output, options);
    char cell[64];
    std::snprintf(cell, sizeof cell, "%.17g", r.resolution);
    say("GeoTIFF " + a.raster + " (Float32, COG, nodata " + std::to_string(static_cast<int>(io::kRasterNodata)) +
        "): " + std::to_string(r.width) + " x " + std::to_string(r.height) + " cells of " + cell + ", " +
        std::to_string(r.cells_with_data) + " with a value (" + r.rule + "), CRS " +
        (r.has_crs ? "the file's" : "none (the file has no CRS)"));
  } else if (format == "octomap" || format == "vdb") {
    export_map(a, tree, format);
  } else if (format == "rosmap") {
    export_ros_map(a, tree);
  } else if (a.slices) {
    const std::uint32_t images = io::write_png_slices(tree, a.output, true);
    say(std::to_string(images) + " PNG slices of " + std::to_string(tree.side()) +
        "^2 pixels, each with a .pgw world file");
  } else if (a.map) {
    io::write_png_height_map(tree, a.output, a.bits);
    const std::string world = io::write_world_file(tree, a.output);
    say(std::to_string(a.bits) + "-bit PNG height map of " + std::to_string(tree.side()) +
        "^2 pixels in voxel units (" + (a.bits == 16 ? "z index + 1" : "z scaled to 1..255") +
        ", 0 empty; --raster dsm for elevations), world file " + world);
  } else {
    io::write_png_occupancy_above(tree, a.output, a.above);
    const std::string world = io::write_world_file(tree, a.output);
    say("PNG occupancy map of voxels at z >= " + std::to_string(a.above) + ", " + std::to_string(tree.side()) +
        "^2 pixels, world file " + world);
  }
  warn_if_crs_is_lost(a, tree, format);
}

}  // namespace

void add_export(CLI::App& app) {
  auto args = std::make_shared<ExportArgs>();
  auto* cmd = app.add_subcommand("export",
                                 "Write a .vol file as PLY, XYZ, LAS, binvox, a dense NPY grid, PNG images, GeoTIFF "
                                 "rasters, OctoMap/OpenVDB or ROS maps");
  cmd->footer(
      "Formats (from OUT's extension unless --format says):\n"
      "  .ply     voxel centres with every attribute as a vertex property (binary; --ascii),\n"
      "           or with --cubes the voxels' outer surface as quads (shared faces removed)\n"
      "  .xyz     \"x y z [attributes]\" text, full double precision\n"
      "  .csv     the same as CSV with PDAL's writers.text header (\"X\",\"Y\",\"Z\",\"Intensity\",...)\n"
      "  .las     LAS 1.4 point format 6 (7 with red/green/blue): voxel centres, attributes\n"
      "           restored, the CRS as WKT\n"
      "  .laz     the same, LASzip-compressed (vola's own LAZ codec)\n"
      "  .binvox  binvox voxel grid\n"
      "  .npy     uint8 0/1 array of shape (S, S, S), index [x, y, z] (depth <= 5)\n"
      "  .png     images in voxel units (pixel = voxel column, values voxel indices, not\n"
      "           elevations), each with a .pgw world file placing its pixels; one of:\n"
      "             --slices               OUT is a directory: one image per z slice, occupied\n"
      "                                    white, named depth<D>-<z>.png (depth <= 5)\n"
      "             --map                  height map: highest occupied z index + 1 per column,\n"
      "                                    0 if empty (16-bit; --bits 8 scales to 1..255)\n"
      "             --occupancy-above Z    black where a column has a voxel at z >= Z, else\n"
      "                                    white (the reference reader's --map)\n"
      "           Images show x to the right and y up (north up); maps stop at depth 7.\n"
      "  .tif     --raster PRODUCT: a Float32 cloud-optimised GeoTIFF (DEFLATE) in the\n"
      "           file's units and CRS, north up, nodata -9999, cropped to the occupied\n"
      "           cells; cells of --resolution R units (default the voxel size; a voxel\n"
      "           column goes to the cell holding its centre). PRODUCT per cell:\n"
      "             dsm        max of the height column (mean point z per voxel, LAS) over\n"
      "                        the voxels; without it, the highest voxel's top face\n"
      "             dtm        min of height (else the lowest voxel's bottom face) over the\n"
      "                        ground voxels (classification 2) if any, else all voxels\n"
      "             intensity  mean intensity of each voxel column's top voxel\n"
      "             density    occupied voxels per square unit; count: occupied voxels\n"
      "  .bt      OctoMap OcTree, binary (liboctomap): every voxel an occupied leaf of\n"
      "           resolution = the voxel size (free leaves: a state map's own, or --free), pruned\n"
      "  .ot      OctoMap OcTree with probabilities: log-odds from a log_odds column (as\n"
      "           vola map writes), else OctoMap's clamping values (0.971 / 0.1192)\n"
      "           OctoMap's cells are floor(x / R): a grid origin that is not a multiple of\n"
      "           the voxel size moves the map under half a voxel onto them, and a map beyond\n"
      "           OctoMap's 32768 cells from 0 (UTM, state plane) moves so that its grid corner\n"
      "           is OctoMap's 0; both with a warning giving the shift.\n"
      "  .vdb     OpenVDB: grid \"occupied\" (BoolGrid) or \"log_odds\" (FloatGrid) with a\n"
      "           log_odds column, and \"free\"/\"free_log_odds\" with --free; transform = voxel\n"
      "           size and the grid origin (index centres on the voxel centres)\n"
      "  .yaml    --band ZMIN:ZMAX: a ROS map (map_server / nav2: OUT.yaml + OUT.pgm, trinary,\n"
      "           as map_saver writes), one cell per voxel column, cropped to the columns\n"
      "           with voxels: occupied where a voxel centre lies in the band (what a robot\n"
      "           of that height meets), free where a free voxel does (a state map from vola\n"
      "           map, or --free), or, with no free voxels, where the column has voxels below\n"
      "           the band and none in it (ground seen, nothing in the way); else unknown\n"
      "Positions are voxel centres in the file's coordinates. --depth K exports the coarser\n"
      "grid of the first K levels (4^K voxels per axis), e.g. to fit a dense format.\n"
      "Examples:\n"
      "  vola export city.vol city.ply\n"
      "  vola export city.vol city_mesh.ply --cubes --depth 4\n"
      "  vola export city.vol city.las\n"
      "  vola export city.vol grid.npy --depth 4\n"
      "  vola export city.vol slices --slices --depth 4\n"
      "  vola export city.vol height.png --map                 # and height.pgw\n"
      "  vola export autzen.vol dsm.tif --raster dsm\n"
      "  vola export autzen.vol dtm.tif --raster dtm --resolution 6\n"
      "  vola export city.vol obstacles.png --occupancy-above 3\n"
      "  vola map scans.txt -o map.vol --voxel-size 0.2 && vola export map.vol map.ot   # occupied, free, log-odds\n"
      "  vola export occupied.vol map.bt --free free.vol    # plain trees: free voxels from another file\n"
      "  vola export map.vol map.vdb\n"
      "  vola export map.vol floor.yaml --band 0.1:1.5        # 2D map for nav2 of a robot 1.5 high\n"
      "  vola export autzen.vol nav.yaml --band 430:450     # a survey in feet: obstacles 430-450 ft, free above\n"
      "                                                     # ground that lies below the band (Autzen's is 400-430)");
  cmd->add_option("input", args->input, "Input .vol file")->required()->check(CLI::ExistingFile);
  cmd->add_option("output", args->output, "Output file (a directory with --slices)")->required();
  cmd->add_option("--format", args->format,
                  "auto (from OUT's extension), ply, xyz, csv, las, binvox, npy, png, tif, octomap, vdb, rosmap")
      ->check(CLI::IsMember(
          {"auto", "ply", "xyz", "csv", "las", "binvox", "npy", "png", "tif", "octomap", "vdb", "rosmap"}))
      ->capture_default_str();
  cmd->add_flag("--ascii", args->ascii, "PLY: ascii instead of binary little-endian");
  cmd->add_flag("--cubes", args->cubes, "PLY: the voxels' outer surface as a quad mesh instead of centre points");
  cmd->add_option("--depth", args->depth, "Export the level-of-detail grid of this depth (1..file depth)")
      ->check(CLI::Range(1, 10));
  cmd->add_flag("--slices", args->slices, "PNG: one image per z slice into the directory OUT");
  cmd->add_flag("--map", args->map, "PNG: top-down height map in voxel units (z index + 1)");
  cmd->add_option("--bits", args->bits, "--map: 16 (exact z + 1) or 8 (scaled)")
      ->check(CLI::IsMember({8, 16}))
      ->capture_default_str();
  cmd->add_option("--occupancy-above", args->above, "PNG: top-down occupancy map of the voxels at z >= Z (voxel units)")
      ->each([args](const std::string&) { args->above_given = true; });
  cmd->add_option("--raster", args->raster, "GeoTIFF: dsm, dtm, intensity, density or count per cell")
      ->check(CLI::IsMember({"dsm", "dtm", "intensity", "density", "count"}, CLI::ignore_case));  // DSM too
  cmd->add_option("--resolution", args->resolution, "--raster: cell size in the file's units (default: the voxel size)")
      ->check(positive_number())
      ->each([args](const std::string&) { args->resolution_given = true; });
  cmd->add_option("--free", args->free,
                  "Maps (.bt, .ot, .vdb, .yaml) from a plain tree: a .vol of the free voxels on the same grid (a state "
                  "map from vola map holds its own)")
      ->check(CLI::ExistingFile);
  cmd->add_option("--band", args->band,
                  "ROS map (.yaml): ZMIN:ZMAX, the heights (file units) whose voxels are obstacles to a robot");
  cmd->add_flag("-q,--quiet", args->quiet, "Print nothing on success but warnings (to stderr)");
  cmd->callback([args] { run_export(*args); });
}

}  // namespace vola::cli
