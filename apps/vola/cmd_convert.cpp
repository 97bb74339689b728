// vola convert: any input the readers know -> .vol, through vola::convert
// (include/vola/convert.hpp). This file only parses the flags and prints the summary
// (run_app.cpp names the flag of an option the library refuses).
#include <chrono>
#include <cstdio>
#include <filesystem>

#include "commands.hpp"
#include "crs_flags.hpp"
#include "filter_flags.hpp"
#include "number_checks.hpp"
#include "option_flags.hpp"
#include "progress.hpp"
#include "vola/convert.hpp"
#include "vola/error.hpp"
#include "vola/file.hpp"
#include "vola/geo/crs.hpp"
#include "vola/io/input.hpp"

namespace vola::cli {

namespace {

struct ConvertArgs {
  std::string input, output, quantize;
  ConvertOptions options;
  std::vector<double> origin, bbox;
  bool no_attributes = false, quiet = false;
  std::vector<int> columns;  // given: x y z, 1-based
};

ConvertOptions options_of(ConvertArgs& a) {
  ConvertOptions options = a.options;
  if (!a.quantize.empty())
    options.quantization = a.quantize == "grid" ? Quantization::grid : Quantization::toolkit;
  if (!a.origin.empty()) options.origin = Point{a.origin[0], a.origin[1], a.origin[2]};
  if (!a.bbox.empty()) options.bbox = Box{{a.bbox[0], a.bbox[1], a.bbox[2]}, {a.bbox[3], a.bbox[4], a.bbox[5]}};
  options.attributes = !a.no_attributes;
  if (!a.columns.empty()) options.columns = std::array<int, 3>{a.columns[0], a.columns[1], a.columns[2]};
  return options;
}

void print_summary(const ConvertArgs& a, const Tree& tree, const ConvertReport& report, double seconds) {
  // An EPT dataset is its node files, not its ept.json.
  const std::uint64_t in_bytes = report.bytes_total.value_or(std::filesystem::file_size(a.input));
  const auto out_bytes = std::filesystem::file_size(a.output);
  const Frame frame = tree.frame();
  const auto definition = geo::crs_definition(tree.georef());
  const std::string crs = definition ? crs_summary_line(std::nullopt, *definition) : "";
  if (!crs.empty())  // as vola info names it: a compound CRS's vertical part too
    std::printf("crs:            %s\n", crs.c_str());
  else if (report.crs_wkt_only)
    std::printf("crs:            WKT from the input, no EPSG code for it (kept in the extension; header code %u)\n",
                tree.georef().epsg);
  else if (!report.epsg)
    std::printf("crs:            none known (header carries the reference's default EPSG:%u)\n", tree.georef().epsg);
  else std::printf("crs:            EPSG:%u\n", *report.epsg);
  const BuildReport& build = report.build;
  const char* unit = report.unit.c_str();
  std::printf("%-16s%llu (%s)\n", (report.unit + " in:").c_str(), static_cast<unsigned long long>(build.points_in),
              a.input.c_str());
  if (build.points_outside)
    std::printf("%s dropped: %llu (outside the grid or not finite)\n", unit,
                static_cast<unsigned long long>(build.points_outside));
  std::printf("voxels out:     %llu at depth %d (%u^3 grid, %s quantization, voxel %.6g)\n",
              static_cast<unsigned long long>(build.voxels), tree.depth(), tree.side(),
              frame.quantization == Quantization::grid ? "grid" : "toolkit", frame.voxel_size);
  const bool smaller = out_bytes <= in_bytes;
  const double ratio = smaller ? (out_bytes ? static_cast<double>(in_bytes) / static_cast<double>(out_bytes) : 0.0)
                               : static_cast<double>(out_bytes) / static_cast<double>(in_bytes ? in_bytes : 1);
  std::printf("file:           %llu bytes (%s), input %llu bytes: %.1fx %s\n",
              static_cast<unsigned long long>(out_bytes), a.output.c_str(), static_cast<unsigned long long>(in_bytes),
              ratio, smaller ? "smaller" : "larger");
  if (report.bytes_read && *report.bytes_read < in_bytes)
    std::printf("input read:     %llu of its %llu bytes (%s nodes outside the level or grid skipped)\n",
                static_cast<unsigned long long>(*report.bytes_read), static_cast<unsigned long long>(in_bytes),
                report.format == "ept" ? "EPT" : "COPC");
  if (build.voxels)
    std::printf("bits per voxel: %.2f (occupied voxels)\n",
                8.0 * static_cast<double>(out_bytes) / static_cast<double>(build.voxels));
  for (const auto& line : report.filters) std::printf("filter:         %s\n", line.c_str());
  std::printf("time:           %.3f s\n", seconds);
}

void run_convert(ConvertArgs& a) {
  check_convert_output(a.input, a.output);
  const auto start = std::chrono::steady_clock::now();
  const ConvertOptions options = options_of(a);
  Progress progress("reading " + a.input);
  ConvertReport report;
  const Tree tree =
      convert(a.input, options, [&progress](std::uint64_t done, std::uint64_t total) { progress.update(done, total); },
              &report);
  progress.finish();
  for (const auto& warning : report.warnings)  // shown with -q too: they are about the result
    std::fprintf(stderr, "vola: warning: %s\n", with_flags(warning).c_str());
  write(tree, a.output, write_options_of(options));
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (!a.quiet) print_summary(a, tree, report, seconds);
}

}  // namespace

std::string known_formats() {
  std::string out;
  for (const auto& f : io::input_formats()) {
    out += (out.empty() ? "" : ", ") + f.name + " (";
    for (std::size_t i = 0; i < f.extensions.size(); ++i) out += (i ? " " : "") + f.extensions[i];
    out += f.extensions.empty() ? "by name only)" : ")";
  }
  return out;
}

void add_convert(CLI::App& app) {
  auto args = std::make_shared<ConvertArgs>();
  auto* cmd = app.add_subcommand("convert", "Convert points, voxel grids, meshes or elevation rasters into a .vol file");
  cmd->footer(
      "Quantization:\n"
      "  grid     floor((p - origin) / voxel-size): what GIS users expect; grids of one voxel\n"
      "           size line up. Default when --voxel-size or --origin is given.\n"
      "  toolkit  the reference toolkit's rounding against the longest bbox side; with the same\n"
      "           input and options the output is byte-identical to the reference's.\n"
      "Maps (OctoMap .bt/.ot through liboctomap, OpenVDB .vdb through OpenVDB):\n"
      "  the occupied cells (.bt/.ot: occupied leaves, pruned nodes expanded; .vdb: the active\n"
      "  voxels of --grid NAME, else of the only grid) become voxels cell for cell at the file's own\n"
      "  voxel size (--voxel-size must equal it), the grid origin on the file's cells; .ot\n"
      "  log-odds and .vdb float/double/int32 values become a column (log_odds, or the grid's\n"
      "  name). Rotated, sheared or non-uniform .vdb transforms are refused.\n"
      "  ROS maps (map_server's MAP.yaml and its PGM or PNG): occupied cells as columns from\n"
      "  z = 0, one voxel or --map-height H high, on the map's own grid (yaw 0 only).\n"
      "Examples:\n"
      "  vola convert city.xyz city.vol --voxel-size 0.5 --assign-crs 32633\n"
      "  vola convert input.txt out.vol --quantize toolkit --depth 3 --nbits 1\n"
      "  vola convert scan.csv scan.vol --voxel-size 0.1 --attribute intensity=4:u16:mean\n"
      "  vola convert points.npy points.vol --depth 5 --compress\n"
      "  vola convert autzen.las autzen_utm.vol --target-crs EPSG:32610 --voxel-size 1\n"
      "  vola convert part.stl part.vol --quantize toolkit --depth 5 --solid\n"
      "  vola convert dem.tif dem.vol --voxel-size 30 --dem-base 0\n"
      "  vola convert map.bt map.vol\n"
      "  vola convert fields.vdb density.vol --grid density\n"
      "  vola convert office.yaml office.vol --map-height 2    # a ROS map as walls 2 m high\n"
      "  vola convert autzen.laz ground.vol --voxel-size 3 --where \"Classification == 2\"\n"
      "  vola convert autzen.laz trees.vol --voxel-size 3 --filter smrf --filter hag --where \"HeightAboveGround > 6\"\n" +
      std::string(kFilterHelp));
  cmd->add_option("input", args->input,
                  "Input file; its first bytes (LAS/LAZ/COPC, E57), else its extension, pick the reader (see --format)")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("output", args->output, "Output .vol file (not the input, nor a name with another format's extension)")->required();
  cmd->add_option(
         "--format", args->options.format,
         "Input format: auto (from the first bytes where they name LAS or E57, else the extension) or one of " +
             known_formats())
      ->capture_default_str();
  cmd->add_option("--depth", args->options.depth, "Tree depth 1..10 (grid side 4^depth); grid mode: default from --voxel-size, and a depth given with it must hold the data (the error names the depth that does)")
      ->check(CLI::Range(1, 10));
  cmd->add_option("--voxel-size", args->options.voxel_size, "Voxel edge in input units (grid mode)")->check(positive_number());
  cmd->add_option("--origin", args->origin, "World position of voxel (0,0,0)'s corner (grid mode), at or below the data's minimum; default: bbox min snapped to the voxel size (a DEM: to its own cells)")
      ->expected(3);
  cmd->add_option("--quantize", args->quantize, "toolkit or grid (default: grid with --voxel-size/--origin, else toolkit)")
      ->check(CLI::IsMember({"toolkit", "grid"}));
  cmd->add_option("--nbits", args->options.nbits, "Payload words per block: 0 = occupancy only, 1 = one 64-bit payload word per block")
      ->check(CLI::Range(0, 64))->capture_default_str();
  cmd->add_flag("--dense", args->options.dense, "Write the reference's dense layout (depth <= 5)");
  add_crs_options(*cmd, args->options.assign_crs, args->options.target_crs, args->options.allow_geographic,
                  "--voxel-size, --origin and --bbox");
  cmd->add_option(
      "--level", args->options.level,
      "COPC and EPT: read only the octree's levels 0..LEVEL (a coarser sample from a small part of the data)");
  cmd->add_option("--grid", args->options.grid,
                  "OpenVDB: the grid to read (default: the only grid, or vola's own occupied grid of a map it wrote; "
                  "several others are refused, listed). NumPy .npz: the array to read (default: the only one, or the "
                  "one named points, xyz, positions, pos, point_cloud, pc or cloud)");
  cmd->add_option("--bbox", args->bbox,
                  "MINX MINY MINZ MAXX MAXY MAXZ: quantize against this box instead of the points' bounds (toolkit: "
                  "points outside it go to the border voxels, as the reference toolkit clips them, with a warning; "
                  "grid: points outside the grid it makes, which covers the box, are dropped)")
      ->expected(6);
  cmd->add_option("--columns", args->columns, "Text: the x y z column numbers, counting from 1 (default: found by name in a header line such as "
                  "'x,y,z,intensity', which also keeps the other columns as attributes; else 1 2 3)")->expected(3)->capture_default_str();
  cmd->add_option("--payload-columns", args->options.payload_columns,
                  "Text with --nbits 1: columns holding payload bytes 0..7 (default: every column after x y z; more "
                  "than 8 are refused)");
  cmd->add_option(
      "--attribute", args->options.text_attributes,
      "Text: keep a column as a per-voxel attribute, NAME=COLUMN[:TYPE[:REDUCTION]], "
      "TYPE u8..u64 i8..i64 f32 f64 (default f32), REDUCTION last mean max min majority (default by NAME, as "
      "for a header's columns: classification, class, label and ids such as treeID majority, "
      "number_of_returns max, the rest mean)");
  cmd->add_option("--skip-lines", args->options.skip_lines, "Text: header lines to skip")->check(non_negative_number());
  cmd->add_flag("--no-attributes", args->no_attributes, "Keep occupancy only, no per-voxel attribute columns (LAS, PLY, PCD, .ot log-odds, .vdb values)");
  cmd->add_flag("--compress", args->options.compress, "compress the levels (context-coded occupancy) and attributes (predicted, zstd): a file only vola reads");
  cmd->add_flag("--compress-max", args->options.compress_max,
                "as --compress, with several context models mixed for every occupancy bit: about a tenth "
                "smaller levels, 2-6x slower to open (for archives and transfer)");
  cmd->add_flag("--solid", args->options.solid, "Mesh: also fill the inside of closed surfaces (flood fill of the outside)");
  cmd->add_option("--dem-base", args->options.dem_base, "DEM: height the voxel columns start from (default: the lowest cell)");
  cmd->add_flag("--dem-surface-only", args->options.dem_surface_only, "DEM: one voxel per cell at its height, no columns");
  cmd->add_option(
         "--map-height", args->options.map_height,
         "ROS map (.yaml): each occupied cell a column this high from z = 0, in the map's units (default: one voxel)")
      ->check(CLI::NonNegativeNumber);
  add_filter_options(*cmd, args->options.filters);
  cmd->add_flag("-q,--quiet", args->quiet, "Print nothing on success but warnings (to stderr)");
  cmd->callback([args] { run_convert(*args); });
}

}  // namespace vola::cli
