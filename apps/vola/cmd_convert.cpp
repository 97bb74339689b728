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
#include "vola/io/las.hpp"
#include "vola/io/npy.hpp"
#include "vola/io/text_points.hpp"

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
};

// What a reader found: the points and, when the input says, its CRS.
struct LoadedPoints {
  PointCloud cloud;
  std::optional<std::uint32_t> epsg;
  std::string wkt;
};

std::string format_of(const ConvertArgs& a) {
  if (a.format != "auto") return a.format;
  std::string ext = std::filesystem::path(a.input).extension().string();
  for (auto& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (ext == ".npy") return "npy";
  if (ext == ".las" || ext == ".laz") return "las";
  if (ext == ".xyz" || ext == ".txt" || ext == ".csv" || ext == ".pts" || ext == ".asc") return "text";
  throw InvalidArgument(a.input + ": cannot tell the format from the extension '" + ext +
                        "'; say --format text or --format npy (LAS, PLY, PCD and meshes come with a later release)");
}

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

LoadedPoints load_las(const ConvertArgs& a) {
  io::LasReader reader(a.input);
  LoadedPoints out;
  out.epsg = reader.header().epsg;
  out.wkt = reader.header().wkt;
  if (!out.epsg && !out.wkt.empty()) out.epsg = geo::epsg_from_wkt(out.wkt);
  Progress progress("reading " + a.input);
  out.cloud = io::las_points(reader, !a.no_attributes, a.nbits > 0,
                             [&](std::uint64_t done, std::uint64_t total) { progress.update(done, total); });
  return out;
}

LoadedPoints load_points(const ConvertArgs& a) {
  const std::string format = format_of(a);
  if (format != "text" && !a.attributes.empty()) throw InvalidArgument("--attribute applies to text input only");
  if (format == "npy") return {io::npy_points(io::read_npy(a.input), a.input, a.nbits > 0), {}, {}};
  if (format == "las") return load_las(a);
  if (format != "text" && format != "xyz" && format != "txt")
    throw InvalidArgument("--format " + format + " is not known (text, npy, las)");
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
  Progress progress("reading " + a.input);
  return {io::read_text_points(a.input, columns,
                               [&](std::uint64_t done, std::uint64_t total) { progress.update(done, total); }),
          {},
          {}};
}

void run_convert(const ConvertArgs& a) {
  const auto start = std::chrono::steady_clock::now();
  BuildOptions options;
  const bool grid_hint = a.voxel_size > 0.0 || !a.origin.empty();
  const std::string quantize = a.quantize.empty() ? (grid_hint ? "grid" : "toolkit") : a.quantize;
  if (quantize == "toolkit") {
    options.quantization = Quantization::toolkit;
    if (a.depth == 0) throw InvalidArgument("--quantize toolkit needs --depth (1..10)");
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

  // Fail on a CRS PROJ does not know before reading gigabytes.
  if (a.crs_given) geo::crs_wkt(a.crs);

  LoadedPoints loaded = load_points(a);
  if (loaded.cloud.size() == 0) throw InvalidArgument(a.input + ": no points");
  // --crs wins over what the input says; without either the header keeps the
  // reference's default code and says so.
  const std::optional<std::uint32_t> epsg = a.crs_given ? std::optional<std::uint32_t>(a.crs) : loaded.epsg;
  options.epsg = epsg.value_or(a.crs);
  BuildReport report;
  Tree tree = build(loaded.cloud, options, &report);
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
  if (!loaded.wkt.empty()) tree.georef().crs_wkt = loaded.wkt;
  else if (epsg && (loaded.epsg || options.quantization == Quantization::grid)) tree.georef().crs_wkt = geo::crs_wkt(*epsg);
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
  std::printf("points in:      %llu (%s)\n", static_cast<unsigned long long>(report.points_in), a.input.c_str());
  if (report.points_outside)
    std::printf("points dropped: %llu (outside the grid or not finite)\n",
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

void add_convert(CLI::App& app) {
  auto args = std::make_shared<ConvertArgs>();
  auto* cmd = app.add_subcommand("convert", "Convert points (XYZ/TXT/CSV text or NPY arrays) into a .vol file");
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
      "  vola convert points.npy points.vol --depth 5 --compress");
  cmd->add_option("input", args->input, "Input points: .las (LAS 1.0-1.4), .xyz .txt .csv .pts .asc (text) or .npy")->required()->check(CLI::ExistingFile);
  cmd->add_option("output", args->output, "Output .vol file")->required();
  cmd->add_option("--format", args->format, "Input format: auto (from the extension), las, text, npy")->capture_default_str();
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
  cmd->add_flag("-q,--quiet", args->quiet, "Print nothing on success");
  cmd->callback([args] { run_convert(*args); });
}

}  // namespace vola::cli
