// vola info: what a .vol file holds, level by level (and what a LAS/LAZ/COPC file says).
#include <charconv>
#include <cmath>
#include <cstdio>
#include <initializer_list>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "commands.hpp"
#include "info_points.hpp"
#include "info_tiles.hpp"
#include "text_output.hpp"
#include "vola/error.hpp"
#include "vola/file.hpp"
#include "vola/geo/crs.hpp"
#include "vola/io/file_checks.hpp"
#include "vola/io/input.hpp"
#include "vola/map/state_map.hpp"

namespace vola::cli {

namespace {

struct InfoArgs {
  std::string file;
  bool json = false;
  bool summary = false;
  std::string grid;
  std::string format = "auto";
};

// A JSON string: control characters escaped, bytes that are not UTF-8 (a name from a
// hostile or Latin-1 file) replaced by U+FFFD, so that the output always parses.
std::string quoted(const std::string& s) {
  return nlohmann::json(s).dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

// How a compressed file's levels are coded (the levels record's flags).
std::string level_coding(const FileLayout& layout) {
  switch (layout.compressed_level_layout) {
    case 2: return "zstd";
    case 3: return "occupancy context-coded";
    case 4: return "occupancy coded by mixed models";
    default: return "levels layout " + std::to_string(layout.compressed_level_layout);
  }
}

// The CRS as PROJ names it, from the file's WKT or its header code; nothing for a file
// with neither (header code 2000 is the reference's placeholder, not Anguilla's grid).
struct NamedCrs {
  std::optional<geo::CrsDescription> description;
  std::string problem;  // why PROJ could not name a CRS the file states
};

// A .vol file by its extension (.vol; .dvol, the reference's dense files) or, under a name
// no reader claims, by its first bytes: the 80 of the header size, or gzip's, which the
// .vol reader then names (the others are read as point files).
bool is_vol_file(const std::string& path) {
  const std::string extension = io::lower_extension(path);
  if (extension == ".vol" || extension == ".dvol") return true;
  for (const auto& format : io::input_formats())
    for (const auto& e : format.extensions)
      if (e == extension) return false;
  unsigned char magic[4] = {};
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (!f) return false;
  const bool whole = std::fread(magic, 1, 4, f) == 4;
  std::fclose(f);
  return whole && ((magic[0] == 80 && magic[1] == 0 && magic[2] == 0 && magic[3] == 0) ||
                   (magic[0] == 0x1f && magic[1] == 0x8b));
}

NamedCrs name_crs(const Tree& tree) {
  NamedCrs out;
  const auto definition = geo::crs_definition(tree.georef());
  if (!definition) return out;
  try {
    out.description = geo::describe_crs(*definition);
  } catch (const Error& e) {
    out.problem = e.what();
  }
  return out;
}

std::string crs_line(const NamedCrs& crs, std::uint32_t header_code) {
  if (crs.description) return geo::crs_summary(*crs.description);
  if (!crs.problem.empty()) return "not readable by PROJ (" + crs.problem + ")";
  return "none stated (header code " + std::to_string(header_code) + ", the reference's placeholder)";
}

std::string json_crs(const NamedCrs& crs) {
  if (!crs.description) return "null";
  const auto& d = *crs.description;
  return "{\"name\": " + quoted(d.name) + ", \"kind\": " + quoted(d.kind) +
         ", \"epsg\": " + (d.epsg ? std::to_string(*d.epsg) : "null") + ", \"unit\": " + quoted(d.horizontal_unit) +
         ", \"vertical\": " + (d.vertical_name.empty() ? "null" : quoted(d.vertical_name)) +
         ", \"vertical_unit\": " + (d.vertical_unit.empty() ? "null" : quoted(d.vertical_unit)) + "}";
}

void run_info(const InfoArgs& a) {
  if (const auto index = tile_index_of(a.file)) {  // a tile set, or its folder
    if (a.summary || !a.grid.empty())
      throw InvalidArgument("--summary and --grid read one file; " + a.file + " is a tile set");
    return print_tile_index_info(*index, a.json);
  }
  io::refuse_non_regular_input(a.file);  // before its first bytes are read
  if (a.format != "auto") {              // the reader named, whatever the extension says
    const std::string format = io::find_input_format(a.file, a.format).name;
    if (format == "las")
      print_point_file_info(a.file, a.summary, a.json);
    else if (format == "ept")
      print_ept_info(a.file, a.summary, a.json);
    else
      print_point_cloud_info(a.file, a.summary, a.json, a.grid, a.format);
    return;
  }
  if (is_point_file(a.file) || !is_vol_file(a.file)) {
    if (!a.grid.empty() && is_point_file(a.file))
      throw OptionError("grid", "applies to OpenVDB (.vdb) and NumPy .npz files; " + a.file + " is a LAS/LAZ file");
    if (is_point_file(a.file)) print_point_file_info(a.file, a.summary, a.json);
    else if (a.grid.empty() && io::find_input_format(a.file, "auto").name == "ept")
      print_ept_info(a.file, a.summary, a.json);
    else
      print_point_cloud_info(a.file, a.summary, a.json, a.grid);
    return;
  }
  if (!a.grid.empty())
    throw OptionError("grid", "applies to OpenVDB (.vdb) and NumPy .npz files; " + a.file + " is a .vol file");
  if (a.summary) throw InvalidArgument("--summary reads the points of a point file; " + a.file + " is a .vol file");
  FileLayout layout;
  const Tree tree = open_mapped(a.file, &layout);
  const Header& h = layout.header;
  const Frame frame = tree.frame();
  const double voxels = static_cast<double>(tree.voxel_count());
  const double bits = voxels > 0 ? 8.0 * static_cast<double>(layout.file_size) / voxels : 0.0;
  const char* mode = h.layout == Layout::dense ? "dense" : "sparse";
  const NamedCrs crs = name_crs(tree);
  std::optional<map::StateCounts> states;
  if (map::is_state_map(tree)) states = map::state_counts(tree);
  // The words a level takes in the file: every dense word, or the sparse tree's blocks.
  const auto file_blocks = [&](int l) {
    return h.layout == Layout::dense ? (std::size_t{1} << (6 * l)) : tree.occupancy(l).size();
  };
  if (a.json) {
    // "crs" is the header's code when it is the data's CRS: a WKT with no EPSG code (US
    // survey-foot LIDAR) leaves the reference's placeholder 2000 there, which is EPSG:2000
    // (Anguilla 1957) to any script that reads it; then null, as "lat" and "lon" are for a
    // file with no CRS at all (computed as if under that placeholder).
    const bool no_crs = !crs.description && crs.problem.empty();
    const bool code_is_the_crs =
        h.epsg != geo::kUnsetEpsg || (crs.description && crs.description->epsg == std::optional<std::uint32_t>(h.epsg));
    // JSON has no infinity or NaN: a reference file may hold them (PROJ's lat/lon of a
    // centre it cannot place is inf; a "nan" input line makes a NaN bbox), printed as null.
    const auto real = [](double v) {
      if (!std::isfinite(v)) return std::string("null");
      char text[32];
      std::snprintf(text, sizeof text, "%.17g", v);
      return std::string(text);
    };
    const auto reals = [&](std::initializer_list<double> values) {
      std::string out;
      for (const double v : values) out += (out.empty() ? "" : ", ") + real(v);
      return out;
    };
    std::printf(
        "{\n  \"file\": %s,\n  \"file_bytes\": %llu,\n  \"version\": %u,\n  \"mode\": \"%s\",\n"
        "  \"depth\": %d,\n  \"side\": %u,\n  \"nbits\": %u,\n  \"crs\": %s,\n  \"lat\": %s,\n"
        "  \"lon\": %s,\n  \"bbox\": [%s],\n"
        "  \"voxels\": %llu,\n  \"bits_per_voxel\": %.4f,\n  \"quantization\": \"%s\",\n"
        "  \"voxel_size\": %s,\n  \"origin\": [%s],\n  \"levels\": [",
        quoted(a.file).c_str(), static_cast<unsigned long long>(layout.file_size), h.version, mode, tree.depth(),
        tree.side(), h.nbits, code_is_the_crs ? std::to_string(h.epsg).c_str() : "null",
        no_crs ? "null" : real(h.lat).c_str(), no_crs ? "null" : real(h.lon).c_str(),
        reals({h.bbox.min[0], h.bbox.min[1], h.bbox.min[2], h.bbox.max[0], h.bbox.max[1], h.bbox.max[2]}).c_str(),
        static_cast<unsigned long long>(tree.voxel_count()), bits,
        frame.quantization == Quantization::grid ? "grid" : "toolkit", real(frame.voxel_size).c_str(),
        reals({frame.origin[0], frame.origin[1], frame.origin[2]}).c_str());
    for (int l = 0; l < tree.depth(); ++l)
      std::printf("%s\n    {\"level\": %d, \"blocks\": %zu, \"occupied\": %llu}", l ? "," : "", l, file_blocks(l),
                  static_cast<unsigned long long>(tree.node_count(l)));
    std::printf("\n  ],\n  \"attributes\": [");
    const auto& columns = tree.attributes().columns();
    for (std::size_t i = 0; i < columns.size(); ++i)
      std::printf("%s\n    {\"name\": %s, \"type\": \"%s\", \"reduction\": \"%s\"}", i ? "," : "",
                  quoted(columns[i].name()).c_str(), std::string(name_of(columns[i].type())).c_str(),
                  std::string(name_of(columns[i].reduction())).c_str());
    std::printf("\n  ]");
    if (states)
      std::printf(",\n  \"state_map\": {\"occupied\": %llu, \"free\": %llu, \"unknown_in_bounds\": %llu}",
                  static_cast<unsigned long long>(states->occupied), static_cast<unsigned long long>(states->free),
                  static_cast<unsigned long long>(states->unknown_in_bounds));
    // "crs_placeholder": the header's code is the reference's placeholder, not the data's
    // CRS ("crs" is null; "crs_wkt" and "crs_named" say what the CRS is when there is one).
    std::printf(
        ",\n  \"compressed\": %s,\n  \"level_coding\": %s,\n  \"extension_bytes\": %llu,\n  \"crs_wkt\": %s,\n"
        "  \"crs_named\": %s,\n  \"crs_placeholder\": %s\n}\n",
        layout.compressed_levels ? "true" : "false",
        layout.compressed_levels ? quoted(level_coding(layout)).c_str() : "null",
        static_cast<unsigned long long>(layout.extension_bytes), quoted(tree.georef().crs_wkt).c_str(),
        json_crs(crs).c_str(), code_is_the_crs ? "false" : "true");
    return;
  }
  std::printf("file:        %s (%llu bytes)\n", a.file.c_str(), static_cast<unsigned long long>(layout.file_size));
  std::printf("header:      version %u, %s, depth %d (%u^3 voxels), nbits %u\n", h.version, mode, tree.depth(),
              tree.side(), h.nbits);
  std::printf("crs:         %s\n", crs_line(crs, h.epsg).c_str());
  // With no CRS the reference writes its placeholder code and the centre's latitude and
  // longitude as if the coordinates were in it: a place on Earth that means nothing.
  const bool placeholder = !crs.description && crs.problem.empty();
  std::printf("header:      EPSG code %u, bbox centre lat %.9f lon %.9f%s\n", h.epsg, h.lat, h.lon,
              placeholder ? " (under the placeholder code: not where the data is)" : "");
  // Coordinates as the shortest text that reads back as the same double: the file's own
  // precision (636001.76, not 636001.76000000001, nor 6.36001760e+05 cut to 9 digits).
  const auto triple = [](const Point& p) { return shortest_text(p[0]) + ", " + shortest_text(p[1]) + ", " + shortest_text(p[2]); };
  std::printf("bbox:        min (%s)\n             max (%s)\n", triple(h.bbox.min).c_str(), triple(h.bbox.max).c_str());
  std::printf("grid:        %s quantization, voxel size %s, origin (%s)%s\n",
              frame.quantization == Quantization::grid ? "grid" : "toolkit", shortest_text(frame.voxel_size).c_str(),
              triple(frame.origin).c_str(), tree.stored_frame() ? "" : " (from the header bbox)");
  if (states)
    std::printf("voxels:      state map (vola map): %llu known, %.2f bits per known voxel (whole file): %llu "
                "occupied, %llu free, %llu unknown in the known voxels' box; the payload words hold the states\n",
                static_cast<unsigned long long>(tree.voxel_count()), bits,
                static_cast<unsigned long long>(states->occupied), static_cast<unsigned long long>(states->free),
                static_cast<unsigned long long>(states->unknown_in_bounds));
  else
    std::printf("voxels:      %llu occupied, %.2f bits per occupied voxel (whole file)\n",
                static_cast<unsigned long long>(tree.voxel_count()), bits);
  std::printf("levels:      level  blocks      occupied cells  bytes\n");
  for (int l = 0; l < tree.depth(); ++l) {
    const std::size_t blocks = file_blocks(l);
    std::printf("             %-5d  %-10zu  %-14llu  %llu\n", l, blocks,
                static_cast<unsigned long long>(tree.node_count(l)),
                static_cast<unsigned long long>(8 * blocks * (h.nbits ? 2 : 1)));
  }
  std::printf("level bytes: %llu%s\n", static_cast<unsigned long long>(layout.level_bytes),
              layout.compressed_levels ? (" (compressed: " + std::to_string(layout.compressed_level_bytes) +
                                          " bytes in the file, " + level_coding(layout) + ")")
                                             .c_str()
                                       : "");
  if (layout.extension_bytes) {
    std::printf("extension:   %llu bytes, version %u\n", static_cast<unsigned long long>(layout.extension_bytes),
                layout.extension_version);
    for (const auto& c : tree.attributes().columns())
      std::printf("attribute:   %s (%s, %s per voxel)\n", c.name().c_str(), std::string(name_of(c.type())).c_str(),
                  std::string(name_of(c.reduction())).c_str());
    if (!tree.georef().crs_wkt.empty()) {
      const auto& wkt = tree.georef().crs_wkt;
      std::printf("crs wkt:     %s%s\n", wkt.substr(0, wkt.find('\n')).c_str(), wkt.find('\n') != std::string::npos ? " ..." : "");
    }
  } else {
    std::printf("extension:   none (a reference-format file)\n");
  }
}

}  // namespace

void add_info(CLI::App& app) {
  auto args = std::make_shared<InfoArgs>();
  auto* cmd = app.add_subcommand("info", "A .vol file's header, levels, bytes and metadata; a LAS/LAZ/COPC file's header, CRS, compression and octree; any other input's size, CRS and bounds");
  cmd->add_option(
         "file", args->file,
         ".vol file, a point file (LAS, LAZ, COPC, PLY, PCD, XYZ, NPY, KITTI), a mesh (OBJ, STL, OFF, PLY, ...), a "
         "voxel grid or map (binvox, NPY occupancy, .bt/.ot, .vdb), a DEM (GeoTIFF, ...) or a tile set (its "
         "index.geojson or folder, from vola tile)")
      ->required()
      ->check(CLI::ExistingPath);
  cmd->footer(
      "Examples:\n"
      "  vola info survey.vol                      # header, levels, bytes, CRS, attribute columns\n"
      "  vola info survey.laz --summary --json     # every point read: bounds, ranges, points per class\n"
      "  vola info tiles/                          # a tile set: grid, CRS, tiles, overviews, missing files");
  cmd->add_flag("--json", args->json, "Print JSON instead of a table (every kind of file)");
  cmd->add_flag("--summary", args->summary,
                "Point files and DEMs: read every point (cell) for their own bounds, column ranges and points per class "
                "(like pdal info --summary)");
  cmd->add_option("--format", args->format,
                  "Input format: auto (a .vol file, or a reader chosen by the first bytes where they name LAS or E57, "
                  "else the extension) or one of " +
                      known_formats())
      ->capture_default_str();
  cmd->add_option("--grid", args->grid,
                  "OpenVDB: the grid to show (a file of several names them when none is given); NumPy .npz: the array");
  cmd->callback([args] { run_info(*args); });
}

}  // namespace vola::cli
