// The conversion pipeline: reader -> points, voxels or triangles -> builder -> tree.
#include "vola/convert.hpp"

#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>
#include <string>
#include <string_view>

#include "filtering.hpp"
#include "georeference.hpp"
#include "options.hpp"
#include "shapes.hpp"
#include "vola/error.hpp"
#include "vola/file.hpp"
#include "vola/geo/crs.hpp"
#include "vola/io/file_checks.hpp"
#include "vola/io/input.hpp"
#include "vola/map/state_map.hpp"

namespace vola {

namespace {

using namespace convert_detail;

// Toolkit quantization puts what lies outside its box on the border voxels, as the
// reference toolkit does (npy2vola clips them; ../shared/golden/fixed_bbox_clip): with a
// box the user gives, the points outside it are counted for a warning, so the walls they
// make on the border are not a surprise. The points are read whole for it (LAS too).
bool clamps_to_bbox(const ConvertOptions& options) {
  return options.bbox && build_options(options, 2000).quantization == Quantization::toolkit;
}

std::uint64_t points_outside(const PointCloud& cloud, const Box& box) {
  std::uint64_t outside = 0;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const double* p = cloud.xyz.data() + 3 * i;
    bool inside = true;
    for (int a = 0; a < 3; ++a) inside = inside && p[a] >= box.min[a] && p[a] <= box.max[a];
    outside += inside ? 0 : 1;
  }
  return outside;
}

io::Input read(const std::string& path, const io::InputFormat& format, const ConvertOptions& options,
               const ConvertProgress& progress, std::vector<filters::StageReport>& filter_report) {
  if (format.name != "text") {
    const std::string why = "apply to text input only (" + path + " is " + format.name + ")";
    if (!options.text_attributes.empty()) throw OptionError("text_attributes", why);
    if (options.columns) throw OptionError("columns", why);
    if (!options.payload_columns.empty()) throw OptionError("payload_columns", why);
    if (options.skip_lines != 0) throw OptionError("skip_lines", why);
  }
  if (format.name != "dem" && (options.dem_base || options.dem_surface_only))
    throw OptionError(options.dem_base ? "dem_base" : "dem_surface_only",
                      "applies to DEM input only (" + path + " is " + format.name + ")");
  io::InputOptions input;
  input.attributes = options.attributes;
  input.payload = options.nbits > 0;
  input.stream = options.target_crs.empty() && !clamps_to_bbox(options);  // reprojection moves the points read whole
  if (format.name == "text") input.text = text_columns(path, options);
  input.dem_base = options.dem_base;
  input.dem_surface_only = options.dem_surface_only;
  if (options.map_height != 0.0 && format.name != "rosmap")
    throw OptionError("map_height", "applies to ROS map input only (" + path + " is " + format.name + ")");
  input.map_height = options.map_height;
  if (options.level && format.name != "las" && format.name != "ept")
    throw OptionError("level", "applies to COPC and EPT input only (" + path + " is " + format.name + ")");
  input.copc_level = options.level;
  // A grid fixed by the bbox lets EPT skip the nodes it misses; filters (SMRF, outliers)
  // see the points around the window, and reprojection moves them, so neither skips.
  if (format.name == "ept" && options.filters.empty() && options.target_crs.empty())
    input.region = grid_region(build_options(options, 2000));
  if (!options.grid.empty() && format.name != "vdb" && format.name != "npy")
    throw OptionError("grid", "applies to OpenVDB and .npz input only (" + path + " is " + format.name + ")");
  input.grid = options.grid;
  input.progress = progress;
  io::Input loaded = options.filters.empty() ? format.read(path, input) : read_filtered(path, format, options, input, filter_report);
  if (options.solid && !loaded.is_mesh())
    throw OptionError("solid", "applies to mesh input (triangles); " + path + " holds none");
  return loaded;
}

// Voxel-grid inputs map one cell to one voxel unless the options ask for another grid:
// then their cell centres are quantized like points. A map's cells are its own: another
// voxel size is refused (resampling occupancy would invent or lose obstacles), and its
// own size given explicitly still maps cell for cell.
std::string size_text(double size) {
  char text[32];
  std::snprintf(text, sizeof text, "%.15g", size);
  return text;
}

bool maps_cell_for_cell(const std::string& path, const io::Input& input, const ConvertOptions& options) {
  if (!input.grid) return false;
  const double size = input.grid->voxel_size;
  const bool own_size = options.voxel_size > 0.0 && std::fabs(options.voxel_size - size) <= 1e-9 * size;
  if (input.grid->fixed_voxel_size && options.voxel_size > 0.0 && !own_size)
    throw OptionError("voxel_size", "is " + size_text(options.voxel_size) + ", but " + path + " is a map of " +
                                        size_text(size) + " cells: give its own size or leave it out");
  return !options.quantization && (options.voxel_size <= 0.0 || (input.grid->fixed_voxel_size && own_size)) &&
         !options.origin && !options.bbox;
}

void check_target_crs(const std::string& target) {
  const std::string definition = crs_definition_of(target);  // its own error for a name
  try {
    geo::crs_wkt(definition);
  } catch (const Error& e) {
    throw OptionError("target_crs", "'" + target.substr(0, 60) + "' is not a CRS PROJ knows: " + e.what());
  }
}

const char* unit_of(const io::Input& input) {
  if (input.is_mesh()) return "triangles";
  return input.terrain ? "cells" : "points";
}

// A file of no points, or none the filters left: said as it is (the file had points).
InvalidArgument no_points(const std::string& path, const io::Input& input, const ConvertOptions& options) {
  if (!options.filters.empty()) {
    std::string stages;
    for (const std::string& f : options.filters) stages += (stages.empty() ? "" : ", ") + f;
    return InvalidArgument(path + ": no point is left after the filters (" + stages + ")");
  }
  return InvalidArgument(path + ": no points" +
                         (input.not_finite ? " with finite coordinates (" + std::to_string(input.not_finite) + " without)"
                                           : std::string()));
}

// A map's free cells the tree does not hold (the reader left them out, or the options
// asked for another grid than the map's), said as a warning: every cell but the occupied
// ones, unknown space too, then reads as free.
std::optional<std::string> dropped_free_cells(const std::string& path, const io::Input& input, const Tree& tree) {
  if (!input.grid || map::is_state_map(tree)) return std::nullopt;
  const std::uint64_t dropped = input.grid->free_cells_dropped + input.grid->free.size();
  if (dropped == 0) return std::nullopt;
  return path + ": the map's " + std::to_string(dropped) + " free cells are not kept: the .vol holds its " +
         std::to_string(input.grid->voxels.size()) +
         " occupied cells, and every other cell, unknown space too, reads as free (vola plan and collide then take "
         "unknown space for free space)";
}

Tree build_tree(const std::string& path, io::Input& input, const ConvertOptions& options, const BuildOptions& build,
                BuildReport& report) {
  if (maps_cell_for_cell(path, input, options)) return tree_from_grid_cells(*input.grid, options.depth, report);
  if (!options.quantization && options.depth == 0 && options.voxel_size <= 0.0)
    throw OptionError("voxel_size",
                      "how fine should the voxels be? Give `voxel_size` (grid quantization: the voxel edge in the "
                      "input's units, e.g. the point spacing) or `depth` (toolkit quantization: 4^D voxels along the "
                      "longest side, 1..10)");
  build.check();
  if (input.build) {  // a streaming reader
    Tree tree = input.build(build, &report);
    if (report.points_in == 0) throw no_points(path, input, options);
    return tree;
  }
  if (input.grid) input.cloud = grid_cell_points(*input.grid, build);
  if (input.is_mesh()) return tree_from_mesh(input, build, options.solid, report);
  if (input.cloud.size() == 0) throw no_points(path, input, options);
  return input.terrain ? tree_from_terrain(input, build, report) : vola::build(input.cloud, build, &report);
}

template <class T>
std::pair<double, double> limits_of() {
  return {static_cast<double>(std::numeric_limits<T>::lowest()), static_cast<double>(std::numeric_limits<T>::max())};
}

// The values an integer attribute type holds; nothing for the floating-point types.
std::optional<std::pair<double, double>> integer_range(ValueType type) {
  switch (type) {
    case ValueType::u8: return limits_of<std::uint8_t>();
    case ValueType::u16: return limits_of<std::uint16_t>();
    case ValueType::u32: return limits_of<std::uint32_t>();
    case ValueType::u64: return limits_of<std::uint64_t>();
    case ValueType::i8: return limits_of<std::int8_t>();
    case ValueType::i16: return limits_of<std::int16_t>();
    case ValueType::i32: return limits_of<std::int32_t>();
    case ValueType::i64: return limits_of<std::int64_t>();
    default: return std::nullopt;
  }
}

// A value an integer column cannot hold is stored clamped to its type (NaN as 0), which
// would pass unseen: --attribute a=4:u8 over values up to 300 reads 255. A mean of
// values in range stays in range, so the points' own values are the ones to check.
std::vector<std::string> clamped_value_warnings(const std::string& path, const PointCloud& cloud) {
  std::vector<std::string> out;
  for (const PointAttribute& a : cloud.attributes) {
    const auto range = integer_range(a.type);
    if (!range) continue;
    std::uint64_t outside = 0, not_numbers = 0;
    double low = std::numeric_limits<double>::infinity(), high = -low;
    for (const double v : a.values) {
      if (std::isnan(v)) {
        ++not_numbers;
        continue;
      }
      const double stored = std::nearbyint(v);
      if (stored >= range->first && stored <= range->second) continue;
      ++outside;
      low = std::min(low, v);
      high = std::max(high, v);
    }
    char text[400];
    if (outside > 0) {
      std::snprintf(text, sizeof text,
                    "%s: attribute %s: %llu of %zu values lie outside %s's range %.17g..%.17g (from %.6g to %.6g): "
                    "they are stored clamped to it; give the attribute a wider TYPE (f32, i32, ...)",
                    path.c_str(), a.name.c_str(), static_cast<unsigned long long>(outside), a.values.size(),
                    std::string(name_of(a.type)).c_str(), range->first, range->second, low, high);
      out.emplace_back(text);
    }
    if (not_numbers > 0) {
      std::snprintf(text, sizeof text, "%s: attribute %s: %llu of %zu values are not numbers: %s stores them as 0",
                    path.c_str(), a.name.c_str(), static_cast<unsigned long long>(not_numbers), a.values.size(),
                    std::string(name_of(a.type)).c_str());
      out.emplace_back(text);
    }
  }
  return out;
}

// A WKT record PROJ cannot read (pdal_warsaw_small.las holds "''") states no CRS: kept,
// it would travel into the .vol and make every export that hands it to GDAL fail. Left
// out, with a warning saying so; nothing when the WKT reads.
std::optional<std::string> drop_unreadable_wkt(const std::string& path, io::Input& input, bool crs_given) {
  if (input.wkt.find_first_not_of(std::string(" \t\r\n\0", 5)) == std::string::npos) {
    input.wkt.clear();
    return std::nullopt;
  }
  try {
    geo::describe_crs(input.wkt, geo::EpsgLookup::own_id_only);
    return std::nullopt;
  } catch (const Error&) {
    const std::string shown = input.wkt.size() > 40 ? input.wkt.substr(0, 40) + "..." : input.wkt;
    input.wkt.clear();
    return path + ": its WKT record (" + shown + ") is not a CRS PROJ can read: it is not kept" +
           (input.epsg  ? " (the EPSG code is)"
            : crs_given ? ""
                        : "; give `assign_crs` if you know the CRS");
  }
}

// An EPSG code PROJ does not know (an E57's coordinateMetadata "EPSG:99999999") stopped
// the conversion with PROJ's words and no file named; it is left out as an unreadable
// WKT is, with a warning saying so.
std::optional<std::string> drop_unknown_epsg(const std::string& path, io::Input& input, bool crs_given) {
  if (!input.epsg || !input.wkt.empty()) return std::nullopt;
  try {
    geo::describe_crs("EPSG:" + std::to_string(*input.epsg), geo::EpsgLookup::own_id_only);
    return std::nullopt;
  } catch (const Error&) {
    const std::uint32_t code = *input.epsg;
    input.epsg.reset();
    return path + ": its CRS, EPSG:" + std::to_string(code) + ", is not a code PROJ knows: it is not kept" +
           (crs_given ? "" : "; give `assign_crs` if you know the CRS");
  }
}

// A grid the points cannot be put on (an extent beyond a double or beyond depth 10, a
// file's grid too large) is said by the core without the file's name; an option's
// error already names what to change.
template <class Build>
Tree name_input_in_errors(const std::string& path, Build&& build) {
  try {
    return build();
  } catch (const OptionError&) {
    throw;
  } catch (const InvalidArgument& e) {
    if (std::string_view(e.what()).starts_with(path)) throw;
    throw InvalidArgument(path + ": " + e.what());
  }
}

}  // namespace

Tree convert(const std::string& path, const ConvertOptions& options, const ConvertProgress& progress,
             ConvertReport* report_out) {
  options.check();
  // A CRS PROJ does not know fails before gigabytes are read.
  if (const std::string given = given_crs(options); !given.empty()) {
    try {
      resolve_crs({}, given);
    } catch (const OptionError&) {
      throw;
    } catch (const Error& e) {  // the option's fault, not the library's: named as such (and C's INVALID_ARGUMENT)
      throw OptionError(options.epsg ? "epsg" : "assign_crs",
                        "'" + given.substr(0, 60) + "' is not a CRS PROJ knows: " + e.what());
    }
  }
  if (!options.target_crs.empty()) check_target_crs(options.target_crs);
  io::refuse_unopenable_input(path);  // the system's reason before anything else
  const io::InputFormat& format = io::find_input_format(path, options.format);
  std::vector<filters::StageReport> filter_report;
  io::Input input = read(path, format, options, progress, filter_report);
  std::vector<std::string> value_warnings = clamped_value_warnings(path, input.cloud);
  if (clamps_to_bbox(options) && !input.is_mesh() && !input.terrain)
    if (const std::uint64_t outside = points_outside(input.cloud, *options.bbox))
      value_warnings.push_back(path + ": " + std::to_string(outside) + " of its " + std::to_string(input.cloud.size()) +
                               " points lie outside the bbox given: toolkit quantization puts them on the border "
                               "voxels, as the reference toolkit clips them; grid quantization (a voxel size) "
                               "drops what lies outside its grid, and `crop` cuts the points first");
  if (const auto dropped = drop_unreadable_wkt(path, input, !given_crs(options).empty()))
    value_warnings.push_back(*dropped);
  if (const auto dropped = drop_unknown_epsg(path, input, !given_crs(options).empty()))
    value_warnings.push_back(*dropped);
  const ResolvedCrs crs =
      options.target_crs.empty() ? input_crs(path, options, input) : reproject(path, options, input);
  const BuildOptions build = build_options(options, header_epsg(crs.epsg));
  refuse_geographic_grid(path, options, input, crs, build.quantization);

  CentreLatLon centre(crs.epsg, crs.wkt.empty() ? input.wkt : crs.wkt);  // PROJ gets ready while the tree is built
  ConvertReport report;
  Tree tree = name_input_in_errors(path, [&] { return build_tree(path, input, options, build, report.build); });
  if (const auto dropped = dropped_free_cells(path, input, tree)) value_warnings.push_back(*dropped);
  // Points the reader left out count as the file's points, dropped as not finite.
  report.build.points_in += input.not_finite;
  report.build.points_outside += input.not_finite;
  const std::optional<std::string> outside_domain = georeference(tree, crs, tree.frame().quantization, centre);
  if (options.nbits > 1) tree.set_nbits(static_cast<std::uint32_t>(options.nbits));
  if (report_out) {
    report.unit = unit_of(input);
    report.format = format.name;
    report.epsg = crs.epsg;
    report.crs_wkt_only = !crs.epsg && !input.wkt.empty();
    if (input.bytes_read) report.bytes_read = input.bytes_read();
    if (input.bytes_total) report.bytes_total = input.bytes_total;
    report.warnings = crs_warnings(path, options, input, crs);
    if (const std::string label = implausible_label(path, crs, tree.georef().bbox); !label.empty())
      report.warnings.push_back(label);
    else if (outside_domain)
      report.warnings.push_back(path + ": " + *outside_domain);
    report.warnings.insert(report.warnings.end(), value_warnings.begin(), value_warnings.end());
    if (report.build.points_in > 0 && tree.voxel_count() == 0)
      report.warnings.push_back(path + ": every one of its " + std::to_string(report.build.points_in) + " " +
                                report.unit +
                                " was dropped (not finite, or outside the grid given): the tree is empty");
    for (const auto& stage : filter_report) report.filters.push_back(describe(stage));
    report.filter_stages = std::move(filter_report);
    *report_out = std::move(report);
  }
  return tree;
}

WriteOptions write_options_of(const ConvertOptions& options) {
  WriteOptions w;
  w.layout = options.dense ? Layout::dense : Layout::sparse;
  w.compress = options.compress || options.compress_max;
  w.mix_occupancy_models = options.compress_max;
  return w;
}

void check_convert_output(const std::string& input, const std::string& output) {
  io::refuse_output_over_input(input, output, "convert writes a new .vol file; give it another name");
  const std::string extension = io::lower_extension(output);
  for (const auto& format : io::input_formats())
    for (const auto& e : format.extensions)
      if (e == extension && e != ".vol" && e != ".dvol")
        throw InvalidArgument(output + ": convert writes a .vol file, not " + format.name + " (" + extension +
                              "); name it .vol, or write points with `vola translate " + input + " " + output +
                              "`, or voxels as points with `vola export FILE.vol " + output + "`");
}

void convert_file(const std::string& input, const std::string& output, const ConvertOptions& options,
                  const ConvertProgress& progress, ConvertReport* report) {
  check_convert_output(input, output);
  options.check();
  const Tree tree = convert(input, options, progress, report);
  const WriteOptions write_options = write_options_of(options);
  write(tree, output, write_options);
}

}  // namespace vola
