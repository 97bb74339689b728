// vola convert: points (XYZ/TXT/CSV text, NPY) -> .vol
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <optional>

#include "commands.hpp"
#include "progress.hpp"
#include "vola/builder.hpp"
#include "vola/error.hpp"
#include "vola/file.hpp"
#include "vola/geo/crs.hpp"
#include "vola/io/input.hpp"
#include "vola/mesh/terrain.hpp"
#include "vola/mesh/voxelize.hpp"

namespace vola::cli {

namespace {

struct ConvertArgs {
  std::string input, output, format = "auto", quantize;
  int depth = 0;
  double voxel_size = 0.0;
  std::vector<double> origin, bbox;
  int nbits = 0;
  bool dense = false, compress = false, quiet = false;
  std::uint32_t crs = 2000;
  bool crs_given = false;
  std::vector<int> columns{1, 2, 3};
  std::vector<int> payload_columns;
  std::vector<std::string> attributes;
  int skip_lines = 0;
  bool no_attributes = false;
  bool solid = false;
  double dem_base = 0.0;
  bool dem_base_given = false, dem_surface_only = false;
};


// NAME=COLUMN[:TYPE[:REDUCTION]], e.g. intensity=4:u16:mean
void parse_attribute(const std::string& spec, io::TextColumns& columns) {
  const auto eq = spec.find('=');
  if (eq == std::string::npos || eq == 0) throw InvalidArgument("--attribute '" + spec + "': expected NAME=COLUMN[:TYPE[:REDUCTION]]");
  PointAttribute a;
  a.name = spec.substr(0, eq);
  std::string rest = spec.substr(eq + 1);
  std::vector<std::string> parts;
  for (std::size_t s = 0;;) {
    const auto c = rest.find(':', s);
    parts.push_back(rest.substr(s, c == std::string::npos ? std::string::npos : c - s));
    if (c == std::string::npos) break;
    s = c + 1;
  }
  int column = 0;
  try {
    column = std::stoi(parts[0]);
  } catch (...) {
    throw InvalidArgument("--attribute '" + spec + "': column '" + parts[0] + "' is not a number");
  }
  if (column < 1) throw InvalidArgument("--attribute '" + spec + "': columns count from 1");
  if (parts.size() > 1) {
    const auto t = parse_value_type(parts[1]);
    if (!t) throw InvalidArgument("--attribute '" + spec + "': type '" + parts[1] + "' is not one of u8 u16 u32 u64 i8 i16 i32 i64 f32 f64");
    a.type = *t;
  }
  if (parts.size() > 2) {
    const auto r = parse_reduction(parts[2]);
    if (!r) throw InvalidArgument("--attribute '" + spec + "': reduction '" + parts[2] + "' is not one of last mean max min majority");
    a.reduction = *r;
  }
  columns.attributes.push_back(std::move(a));
  columns.attribute_columns.push_back(column - 1);
}

io::TextColumns text_columns(const ConvertArgs& a) {
  io::TextColumns columns;
  if (a.columns.size() != 3) throw InvalidArgument("--columns takes three column numbers (x y z)");
  for (int c : a.columns)
    if (c < 1) throw InvalidArgument("--columns: columns count from 1");
  columns.x = a.columns[0] - 1;
  columns.y = a.columns[1] - 1;
  columns.z = a.columns[2] - 1;
  columns.skip_lines = a.skip_lines;
  if (a.nbits > 0) {
    if (!a.payload_columns.empty()) {
      for (int c : a.payload_columns) columns.payload.push_back(c - 1);
    } else {
      // The reference's xyz2vola: every column after x y z is a payload byte.
      const int n = io::count_text_columns(a.input, a.skip_lines);
      const int last_xyz = std::max({columns.x, columns.y, columns.z});
      for (int c = last_xyz + 1; c < n && columns.payload.size() < 8; ++c) columns.payload.push_back(c);
    }
  }
  for (const auto& spec : a.attributes) parse_attribute(spec, columns);
  return columns;
}

// `progress` must outlive the returned Input: streaming readers report through it later.
io::Input load_input(const ConvertArgs& a, Progress& progress) {
  const io::InputFormat& format = io::find_input_format(a.input, a.format);
  if (format.name != "text" && !a.attributes.empty()) throw InvalidArgument("--attribute applies to text input only");
  io::InputOptions options;
  options.attributes = !a.no_attributes;
  options.payload = a.nbits > 0;
  options.stream = true;
  if (format.name == "text") options.text = text_columns(a);
  if (format.name != "dem" && (a.dem_base_given || a.dem_surface_only))
    throw InvalidArgument("--dem-base and --dem-surface-only apply to DEM input");
  if (a.dem_base_given) options.dem_base = a.dem_base;
  options.dem_surface_only = a.dem_surface_only;
  options.progress = [&progress](std::uint64_t done, std::uint64_t total) { progress.update(done, total); };
  io::Input input = format.read(a.input, options);
  if (!input.epsg && !input.wkt.empty()) input.epsg = geo::epsg_from_wkt(input.wkt);
  return input;
}

// Voxel-grid inputs map one cell to one voxel unless the user asked for another grid:
// then their cell centres are quantized like points.
bool maps_one_to_one(const io::Input& input, const ConvertArgs& a) {
  return input.grid && a.quantize.empty() && a.voxel_size <= 0.0 && a.origin.empty() && a.bbox.empty();
}

Tree build_from_grid(const io::VoxelGrid& grid, int requested_depth, BuildReport& report) {
  const std::uint32_t largest = std::max({grid.dims[0], grid.dims[1], grid.dims[2], 1u});
  int depth = requested_depth;
  if (depth == 0)
    for (depth = 1; depth < kMaxDepth && side_of(depth) < largest; ++depth) {
    }
  if (side_of(depth) < largest)
    throw InvalidArgument("a " + std::to_string(largest) + "-cell grid does not fit depth " + std::to_string(depth) +
                          " (" + std::to_string(side_of(depth)) + " voxels per axis)");
  Tree tree = build_from_voxels(grid.voxels, depth);
  Frame frame;
  frame.quantization = Quantization::grid;
  frame.origin = grid.origin;
  frame.voxel_size = grid.voxel_size;
  tree.set_frame(frame);
  Box box{grid.origin, grid.origin};
  for (int i = 0; i < 3; ++i) box.max[i] += grid.voxel_size * grid.dims[i];
  tree.georef().bbox = box;
  report.points_in = grid.voxels.size();
  report.voxels = tree.voxel_count();
  return tree;
}

// Cell centres of a voxel-grid input, as points.
PointCloud grid_centres(const io::VoxelGrid& grid) {
  PointCloud cloud;
  cloud.xyz.reserve(3 * grid.voxels.size());
  for (const Voxel& v : grid.voxels) {
    cloud.xyz.push_back(grid.origin[0] + (v.x + 0.5) * grid.voxel_size);
    cloud.xyz.push_back(grid.origin[1] + (v.y + 0.5) * grid.voxel_size);
    cloud.xyz.push_back(grid.origin[2] + (v.z + 0.5) * grid.voxel_size);
  }
  return cloud;
}

// Triangles -> surface voxels (and the inside with --solid). Toolkit mode frames the
// vertices' bbox, like the points' bbox of a point cloud.
Tree build_from_mesh(const io::Input& input, BuildOptions options, bool solid, BuildReport& report) {
  if (options.payload) throw InvalidArgument("--nbits: mesh input carries no payload");
  const Box bbox = options.bbox ? *options.bbox : mesh::triangle_bounds(input.triangles);
  const Quantizer quantizer = resolve_quantizer(bbox, options);
  mesh::VoxelizeOptions voxelize;
  voxelize.solid = solid;
  mesh::VoxelizeReport voxels;
  Tree tree = mesh::voxelize(input.triangles, quantizer, voxelize, &voxels);
  tree.georef().bbox = bbox;
  report.points_in = voxels.triangles;
  report.points_outside = voxels.skipped + voxels.outside;
  report.voxels = tree.voxel_count();
  return tree;
}

// DEM cells -> columns of voxels from the base height to each cell's height. The frame
// covers the base too, so that the columns fit.
Tree build_from_terrain(const io::Input& input, BuildOptions options, BuildReport& report) {
  if (options.payload) throw InvalidArgument("--nbits: DEM input carries no payload");
  Box bbox = input.cloud.bounds();
  if (!input.terrain_surface_only) {
    bbox.min[2] = std::min(bbox.min[2], input.terrain_base);
    bbox.max[2] = std::max(bbox.max[2], input.terrain_base);
  }
  if (options.bbox) bbox = *options.bbox;
  const Quantizer quantizer = resolve_quantizer(bbox, options);
  mesh::TerrainOptions columns;
  columns.base = input.terrain_base;
  columns.surface_only = input.terrain_surface_only;
  Tree tree = mesh::terrain_columns(input.cloud, quantizer, columns, &report);
  tree.georef().bbox = bbox;
  return tree;
}

void run_convert(const ConvertArgs& a) {
  const auto start = std::chrono::steady_clock::now();
  // Fail on a CRS PROJ does not know before reading gigabytes.
  if (a.crs_given) geo::crs_wkt(a.crs);
  Progress progress("reading " + a.input);
  io::Input loaded = load_input(a, progress);
  if (a.solid && !loaded.is_mesh()) throw InvalidArgument("--solid applies to mesh input (triangles)");
  const bool one_to_one = maps_one_to_one(loaded, a);

  BuildOptions options;
  const bool grid_hint = a.voxel_size > 0.0 || !a.origin.empty();
  const std::string quantize = a.quantize.empty() ? (grid_hint ? "grid" : "toolkit") : a.quantize;
  if (one_to_one) {
    options.quantization = Quantization::grid;
  } else if (quantize == "toolkit") {
    options.quantization = Quantization::toolkit;
    if (a.depth == 0)
      throw InvalidArgument(a.quantize.empty()
                                ? "how fine should the voxels be? Give --voxel-size S (grid mode, S in the input's units, "
                                  "e.g. the point spacing) or --depth D (toolkit mode: 4^D voxels along the longest side, 1..10)"
                                : "--quantize toolkit needs --depth (1..10)");
    if (a.voxel_size > 0.0 || !a.origin.empty())
      throw InvalidArgument("--voxel-size and --origin apply to --quantize grid; toolkit mode derives the grid from the bbox");
  } else if (quantize == "grid") {
    options.quantization = Quantization::grid;
    if (a.depth == 0 && a.voxel_size <= 0.0) throw InvalidArgument("--quantize grid needs --voxel-size or --depth");
  } else {
    throw InvalidArgument("--quantize " + quantize + ": expected toolkit or grid");
  }
  options.depth = a.depth;
  options.voxel_size = a.voxel_size;
  if (!a.origin.empty()) options.origin = Point{a.origin[0], a.origin[1], a.origin[2]};
  if (!a.bbox.empty()) {
    Box b{{a.bbox[0], a.bbox[1], a.bbox[2]}, {a.bbox[3], a.bbox[4], a.bbox[5]}};
    for (int i = 0; i < 3; ++i)
      if (!(b.min[i] <= b.max[i])) throw InvalidArgument("--bbox: each minimum must be <= its maximum");
    options.bbox = b;
  }
  options.payload = a.nbits > 0;
  // --crs wins over what the input says; without either the header keeps the
  // reference's default code and says so.
  const std::optional<std::uint32_t> epsg = a.crs_given ? std::optional<std::uint32_t>(a.crs) : loaded.epsg;
  options.epsg = epsg.value_or(a.crs);
  BuildReport report;
  Tree tree;
  if (one_to_one) {
    tree = build_from_grid(*loaded.grid, a.depth, report);
  } else if (loaded.build) {
    tree = loaded.build(options, &report);
    if (report.points_in == 0) throw InvalidArgument(a.input + ": no points");
  } else {
    if (loaded.grid) loaded.cloud = grid_centres(*loaded.grid);
    if (loaded.is_mesh()) {
      tree = build_from_mesh(loaded, options, a.solid, report);
    } else {
      if (loaded.cloud.size() == 0) throw InvalidArgument(a.input + ": no points");
      tree = loaded.terrain ? build_from_terrain(loaded, options, report) : build(loaded.cloud, options, &report);
    }
  }
  progress.finish();
  tree.georef().epsg = options.epsg;
  // lat/lon of the bbox centre through PROJ, from the code or else the input's WKT.
  // A CRS PROJ cannot place leaves them 0 rather than failing the conversion, unless the
  // user named it.
  try {
    const auto [lat, lon] = epsg || loaded.wkt.empty() ? geo::centre_lat_lon(options.epsg, tree.georef().bbox)
                                                       : geo::centre_lat_lon(loaded.wkt, tree.georef().bbox);
    tree.georef().lat = lat;
    tree.georef().lon = lon;
  } catch (const Error&) {
    if (a.crs_given) throw;
  }
  // The CRS as WKT goes into the extension whenever we know it, except for a toolkit
  // conversion of CRS-less input, which stays byte-identical to the reference's file.
  const bool input_has_crs = loaded.epsg || !loaded.wkt.empty();
  if (a.crs_given && (input_has_crs || options.quantization == Quantization::grid))
    tree.georef().crs_wkt = geo::crs_wkt(a.crs);
  else if (!a.crs_given && !loaded.wkt.empty())
    tree.georef().crs_wkt = loaded.wkt;
  else if (!a.crs_given && loaded.epsg)
    tree.georef().crs_wkt = geo::crs_wkt(*loaded.epsg);
  if (a.nbits > 1) tree.set_nbits(static_cast<std::uint32_t>(a.nbits));

  WriteOptions w;
  w.layout = a.dense ? Layout::dense : Layout::sparse;
  w.compress = a.compress;
  write(tree, a.output, w);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (a.quiet) return;
  const auto in_bytes = std::filesystem::file_size(a.input);
  const auto out_bytes = std::filesystem::file_size(a.output);
  const Frame frame = tree.frame();
  if (!epsg && !loaded.wkt.empty())
    std::printf("crs:            WKT from the input, no EPSG code for it (kept in the extension; header code %u)\n", options.epsg);
  else if (!epsg)
    std::printf("crs:            none known (header carries the reference's default EPSG:%u)\n", options.epsg);
  else std::printf("crs:            EPSG:%u\n", *epsg);
  const char* unit = loaded.is_mesh() ? "triangles" : (loaded.terrain ? "cells" : "points");
  std::printf("%-16s%llu (%s)\n", (std::string(unit) + " in:").c_str(), static_cast<unsigned long long>(report.points_in),
              a.input.c_str());
  if (report.points_outside)
    std::printf("%s dropped: %llu (outside the grid or not finite)\n", unit,
                static_cast<unsigned long long>(report.points_outside));
  std::printf("voxels out:     %llu at depth %d (%u^3 grid, %s quantization, voxel %.6g)\n",
              static_cast<unsigned long long>(report.voxels), tree.depth(), tree.side(),
              frame.quantization == Quantization::grid ? "grid" : "toolkit", frame.voxel_size);
  std::printf("file:           %llu bytes (%s), input %llu bytes: %.1fx smaller\n",
              static_cast<unsigned long long>(out_bytes), a.output.c_str(), static_cast<unsigned long long>(in_bytes),
              out_bytes ? static_cast<double>(in_bytes) / static_cast<double>(out_bytes) : 0.0);
  if (report.voxels)
    std::printf("bits per voxel: %.2f (occupied voxels)\n",
                8.0 * static_cast<double>(out_bytes) / static_cast<double>(report.voxels));
  std::printf("time:           %.3f s\n", seconds);
}

}  // namespace

// "las (.las .laz), text (.xyz ...), ...": every reader this build has, for the help.
std::string known_formats() {
  std::string out;
  for (const auto& f : io::input_formats()) {
    out += (out.empty() ? "" : ", ") + f.name + " (";
    for (std::size_t i = 0; i < f.extensions.size(); ++i) out += (i ? " " : "") + f.extensions[i];
    out += ")";
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
      "Examples:\n"
      "  vola convert city.xyz city.vol --voxel-size 0.5 --crs 32633\n"
      "  vola convert input.txt out.vol --quantize toolkit --depth 3 --nbits 1\n"
      "  vola convert scan.csv scan.vol --voxel-size 0.1 --attribute intensity=4:u16:mean\n"
      "  vola convert points.npy points.vol --depth 5 --compress\n"
      "  vola convert part.stl part.vol --quantize toolkit --depth 5 --solid\n"
      "  vola convert dem.tif dem.vol --voxel-size 30 --dem-base 0");
  cmd->add_option("input", args->input, "Input file; its extension picks the reader (see --format)")->required()->check(CLI::ExistingFile);
  cmd->add_option("output", args->output, "Output .vol file")->required();
  cmd->add_option("--format", args->format, "Input format: auto (from the extension) or one of " + known_formats())->capture_default_str();
  cmd->add_option("--depth", args->depth, "Tree depth 1..10 (grid side 4^depth); grid mode: default from --voxel-size")
      ->check(CLI::Range(1, 10));
  cmd->add_option("--voxel-size", args->voxel_size, "Voxel edge in input units (grid mode)")->check(CLI::PositiveNumber);
  cmd->add_option("--origin", args->origin, "World position of voxel (0,0,0)'s corner (grid mode); default: bbox min snapped to the voxel size")
      ->expected(3);
  cmd->add_option("--quantize", args->quantize, "toolkit or grid (default: grid with --voxel-size/--origin, else toolkit)")
      ->check(CLI::IsMember({"toolkit", "grid"}));
  cmd->add_option("--nbits", args->nbits, "Payload words per block: 0 = occupancy only, 1 = one 64-bit payload word per block")
      ->check(CLI::Range(0, 64))->capture_default_str();
  cmd->add_flag("--dense", args->dense, "Write the reference's dense layout (depth <= 5)");
  cmd->add_option("--crs", args->crs, "EPSG code of the input coordinates (header lat/lon from it)")
      ->each([args](const std::string&) { args->crs_given = true; })->capture_default_str();
  cmd->add_option("--bbox", args->bbox, "MINX MINY MINZ MAXX MAXY MAXZ: quantize against this box instead of the points' bounds")
      ->expected(6);
  cmd->add_option("--columns", args->columns, "Text: the x y z column numbers, counting from 1")->expected(3)->capture_default_str();
  cmd->add_option("--payload-columns", args->payload_columns,
                  "Text with --nbits 1: columns holding payload bytes 0..7 (default: every column after x y z)");
  cmd->add_option("--attribute", args->attributes,
                  "Text: keep a column as a per-voxel attribute, NAME=COLUMN[:TYPE[:REDUCTION]], "
                  "TYPE u8..u64 i8..i64 f32 f64 (default f32), REDUCTION last mean max min majority (default mean)");
  cmd->add_option("--skip-lines", args->skip_lines, "Text: header lines to skip")->check(CLI::NonNegativeNumber);
  cmd->add_flag("--no-attributes", args->no_attributes, "LAS: keep occupancy only, no per-voxel attribute columns");
  cmd->add_flag("--compress", args->compress, "zstd-compress the levels and attributes (a file only vola reads)");
  cmd->add_flag("--solid", args->solid, "Mesh: also fill the inside of closed surfaces (flood fill of the outside)");
  cmd->add_option("--dem-base", args->dem_base, "DEM: height the voxel columns start from (default: the lowest cell)")
      ->each([args](const std::string&) { args->dem_base_given = true; });
  cmd->add_flag("--dem-surface-only", args->dem_surface_only, "DEM: one voxel per cell at its height, no columns");
  cmd->add_flag("-q,--quiet", args->quiet, "Print nothing on success");
  cmd->callback([args] { run_convert(*args); });
}

}  // namespace vola::cli
