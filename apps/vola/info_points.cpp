// vola info on input files: a LAS, LAZ or COPC file's header, (E)VLRs, compression and
// COPC octree, read without decoding a point; any other point file's count, CRS and
// columns; a mesh's triangles, a voxel grid's or map's cells, a DEM's cells with their
// bounds; with --summary every point read; with --json the same as one JSON object.
#include "info_points.hpp"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "vola/analysis/census.hpp"
#include "vola/crs_rules.hpp"
#include "vola/error.hpp"
#include "vola/geo/crs.hpp"
#include "vola/io/e57.hpp"
#include "vola/io/ept.hpp"
#include "vola/io/input.hpp"
#include "vola/io/las.hpp"
#include "vola/io/npy.hpp"
#include "vola/io/text_points.hpp"
#include "vola/io/translate.hpp"
#include "vola/number_text.hpp"

namespace vola::cli {

namespace {

using nlohmann::ordered_json;

std::string crs_definition(const std::string& wkt, const std::optional<std::uint32_t>& epsg) {
  return !wkt.empty() ? wkt : epsg ? "EPSG:" + std::to_string(*epsg) : "";
}

std::string crs_text(const std::string& definition) {
  if (definition.empty()) return "none stated";
  try {
    return geo::crs_summary(geo::describe_crs(definition));
  } catch (const Error& e) {
    return "not readable by PROJ (" + std::string(e.what()) + ")";
  }
}

// The CRS as PROJ names it (null when none is stated; "problem" when PROJ cannot read it).
ordered_json crs_json(const std::string& wkt, const std::optional<std::uint32_t>& epsg) {
  const std::string definition = crs_definition(wkt, epsg);
  if (definition.empty()) return nullptr;
  ordered_json out;
  try {
    const geo::CrsDescription d = geo::describe_crs(definition);
    out["name"] = d.name;
    out["kind"] = d.kind;
    out["epsg"] = d.epsg ? ordered_json(*d.epsg) : ordered_json(nullptr);
    out["unit"] = d.horizontal_unit;
    out["vertical"] = d.vertical_name.empty() ? ordered_json(nullptr) : ordered_json(d.vertical_name);
    out["vertical_unit"] = d.vertical_unit.empty() ? ordered_json(nullptr) : ordered_json(d.vertical_unit);
  } catch (const Error& e) {
    out["problem"] = e.what();
  }
  out["wkt"] = wkt;
  return out;
}

ordered_json xyz(const double* v) { return ordered_json::array({v[0], v[1], v[2]}); }

// Coordinates at the file's precision: a LAS coordinate is offset + scale * integer, and a
// header's doubles carry the binary noise of that sum (848935.2000000001 for 848935.20 at
// scale 0.01); rounded to the decimals of its scale and offset they print as the file
// means them (LasHeader::coordinate_decimals).
ordered_json xyz_at(const double* v, const io::LasHeader& header) {
  ordered_json out = ordered_json::array();
  for (int i = 0; i < 3; ++i) {
    if (!std::isfinite(v[i])) {
      out.push_back(v[i]);
      continue;
    }
    const double unit = std::pow(10.0, header.coordinate_decimals(i));
    out.push_back(std::round(v[i] * unit) / unit);
  }
  return out;
}

// "(x, y, z)" at the LAS file's precision, for the text report.
std::string las_point_text(const double* v, const io::LasHeader& header) {
  std::string out = "(";
  for (int i = 0; i < 3; ++i) {
    char number[64];
    std::snprintf(number, sizeof number, "%.*f", header.coordinate_decimals(i), v[i]);
    out += (i ? ", " : "") + std::string(number);
  }
  return out + ")";
}

void print_compression(const io::LasHeader& hd) {
  const auto& z = *hd.laszip;
  const char* kinds[] = {"none", "point-wise", "point-wise chunked", "layered chunked"};
  std::printf("laz:         compressor %u (%s), LASzip %u.%u r%u, ", z.compressor,
              z.compressor <= 3 ? kinds[z.compressor] : "?", z.version_major, z.version_minor, z.revision);
  if (z.compressor == 1)
    std::printf("one stream, not chunked");  // its chunk size field means nothing
  else if (z.chunk_size == io::laz::kVariableChunkSize)
    std::printf("variable chunks");
  else if (z.chunk_size == 0)
    std::printf("chunk size 0 (one chunk of every point)");
  else
    std::printf("chunks of %u points", z.chunk_size);
  if (z.compressor != 1) std::printf(", %zu chunk%s", hd.laz_chunks.size(), hd.laz_chunks.size() == 1 ? "" : "s");
  std::printf("\nitems:      ");
  for (const auto& item : z.items) std::printf(" %s", io::laz::describe_item(item).c_str());
  std::printf("\n");
}

void print_copc(const io::CopcHierarchy& copc) {
  std::uint64_t points = 0;
  std::vector<std::uint64_t> per_level(static_cast<std::size_t>(copc.levels), 0);
  std::vector<std::size_t> nodes_per_level(static_cast<std::size_t>(copc.levels), 0);
  for (const auto& n : copc.nodes) {
    points += n.point_count;
    per_level[static_cast<std::size_t>(n.level)] += n.point_count;
    ++nodes_per_level[static_cast<std::size_t>(n.level)];
  }
  const auto& i = copc.info;
  std::printf("copc:        octree of %d levels, %zu nodes with points (%llu points), %zu hierarchy pages\n",
              copc.levels, copc.nodes.size(), static_cast<unsigned long long>(points), copc.pages);
  std::printf("             cube centre (%.9g, %.9g, %.9g), half size %.9g, root spacing %.9g\n", i.center[0],
              i.center[1], i.center[2], i.halfsize, i.spacing);
  for (std::size_t l = 0; l < per_level.size(); ++l)
    std::printf("             level %zu: %zu nodes, %llu points, spacing %.6g\n", l, nodes_per_level[l],
                static_cast<unsigned long long>(per_level[l]), i.spacing / static_cast<double>(std::uint64_t{1} << l));
}

ordered_json copc_json(const io::CopcHierarchy& copc) {
  ordered_json levels = ordered_json::array();
  std::vector<std::uint64_t> per_level(static_cast<std::size_t>(copc.levels), 0);
  std::vector<std::size_t> nodes_per_level(static_cast<std::size_t>(copc.levels), 0);
  for (const auto& n : copc.nodes) {
    per_level[static_cast<std::size_t>(n.level)] += n.point_count;
    ++nodes_per_level[static_cast<std::size_t>(n.level)];
  }
  for (std::size_t l = 0; l < per_level.size(); ++l)
    levels.push_back({{"level", l},
                      {"nodes", nodes_per_level[l]},
                      {"points", per_level[l]},
                      {"spacing", copc.info.spacing / static_cast<double>(std::uint64_t{1} << l)}});
  return {{"levels", copc.levels},
          {"nodes", copc.nodes.size()},
          {"pages", copc.pages},
          {"center", xyz(copc.info.center.data())},
          {"halfsize", copc.info.halfsize},
          {"spacing", copc.info.spacing},
          {"per_level", std::move(levels)}};
}

// Every point read: the count, the points' own bounds, each column's range and, for a
// classification column, the count per class (as pdal info --summary reports them),
// gathered a chunk of points at a time.
class Summary {
 public:
  void add(const PointCloud& chunk) {
    if (names_.empty())
      for (const auto& a : chunk.attributes) {
        names_.push_back(a.name);
        ranges_.emplace_back(INFINITY, -INFINITY);
      }
    points_ += chunk.size();
    for (std::size_t i = 0; i < chunk.size(); ++i) {
      const double* p = chunk.xyz.data() + 3 * i;
      if (!(std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2]))) continue;
      bounded_ = true;
      for (int a = 0; a < 3; ++a) box_.min[a] = std::min(box_.min[a], p[a]), box_.max[a] = std::max(box_.max[a], p[a]);
    }
    for (std::size_t c = 0; c < chunk.attributes.size() && c < ranges_.size(); ++c) {
      auto& [lo, hi] = ranges_[c];
      for (const double v : chunk.attributes[c].values) lo = std::min(lo, v), hi = std::max(hi, v);  // NaN left out
      if (names_[c] == "classification")
        for (const double v : chunk.attributes[c].values) ++classes_[static_cast<int>(v)];
    }
  }
  std::uint64_t points() const { return points_; }
  Box box() const { return bounded_ ? box_ : Box{}; }
  // Each column with a value: its name and range.
  std::vector<std::pair<std::string, std::pair<double, double>>> columns() const {
    std::vector<std::pair<std::string, std::pair<double, double>>> out;
    for (std::size_t c = 0; c < names_.size(); ++c)
      if (ranges_[c].first <= ranges_[c].second) out.emplace_back(names_[c], ranges_[c]);
    return out;
  }
  const std::map<int, std::uint64_t>& classes() const { return classes_; }

 private:
  std::uint64_t points_ = 0;
  bool bounded_ = false;
  Box box_{{INFINITY, INFINITY, INFINITY}, {-INFINITY, -INFINITY, -INFINITY}};
  std::vector<std::string> names_;
  std::vector<std::pair<double, double>> ranges_;
  std::map<int, std::uint64_t> classes_;
};

Summary summarise(const PointCloud& cloud) {
  Summary s;
  s.add(cloud);
  return s;
}

// A LAS/LAZ/COPC file's every record, every dimension, a chunk at a time.
Summary summarise_las(io::LasReader& reader) {
  Summary s;
  io::for_each_las_chunk(reader, [&](const PointCloud& chunk) { s.add(chunk); });
  return s;
}

// A value as short as reads back: a float's shortest text when the value is one (PLY and
// PCD coordinates, float columns: 0.1f is "0.1", not 0.10000000149011612), else the
// double's (1234567890.12345 stays whole, where 9 significant digits made it 1.23456789e+09).
std::string value_text(double v) {
  char text[32];
  const float f = static_cast<float>(v);
  const auto r = std::isfinite(v) && static_cast<double>(f) == v ? std::to_chars(text, text + sizeof text, f)
                                                                 : std::to_chars(text, text + sizeof text, v);
  return std::string(text, r.ptr);
}

std::string point_text(const std::array<double, 3>& p) {
  return "(" + value_text(p[0]) + ", " + value_text(p[1]) + ", " + value_text(p[2]) + ")";
}

// The LAS minor version whose class table names the codes (4: any other input's, read as
// LAS 1.4's).
int las_minor(const io::LasHeader* header) { return header && header->version_major == 1 ? header->version_minor : 4; }

// `header`: a LAS file's, for coordinates at its precision (null: each value as short as
// reads back).
void print_summary(const Summary& summary, const io::LasHeader* header = nullptr) {
  const Box box = summary.box();
  std::printf("summary:     %llu points read\n", static_cast<unsigned long long>(summary.points()));
  if (summary.points() == 0)
    std::printf("             no points, so no bounds\n");
  else if (header)
    std::printf("             min %s\n             max %s (the points')\n",
                las_point_text(box.min.data(), *header).c_str(), las_point_text(box.max.data(), *header).c_str());
  else
    std::printf("             min %s\n             max %s (the points')\n", point_text(box.min).c_str(),
                point_text(box.max).c_str());
  for (const auto& [name, range] : summary.columns())
    std::printf("column:      %s: %s .. %s\n", name.c_str(), value_text(range.first).c_str(),
                value_text(range.second).c_str());
  for (const auto& [code, n] : summary.classes())
    std::printf("class:       %3d %-38s %llu\n", code,
                std::string(analysis::asprs_class_name(code, las_minor(header))).c_str(),
                static_cast<unsigned long long>(n));
}

// print_summary's figures as JSON (pdal info --summary's content, vola's names).
// `header`: a LAS file's, for coordinates at its precision (null: as read).
ordered_json summary_json(const Summary& summary, const io::LasHeader* header = nullptr) {
  const Box box = summary.box();
  const auto coordinates = [header](const Point& p) { return header ? xyz_at(p.data(), *header) : xyz(p.data()); };
  ordered_json out = {
      {"points_read", summary.points()},
      {"bounds", summary.points() > 0 ? ordered_json({{"min", coordinates(box.min)}, {"max", coordinates(box.max)}})
                                      : ordered_json(nullptr)}};
  ordered_json columns = ordered_json::object();
  for (const auto& [name, range] : summary.columns()) columns[name] = {{"min", range.first}, {"max", range.second}};
  out["columns"] = std::move(columns);
  if (!summary.classes().empty()) {
    ordered_json list = ordered_json::array();
    for (const auto& [code, n] : summary.classes())
      list.push_back(
          {{"code", code}, {"name", std::string(analysis::asprs_class_name(code, las_minor(header)))}, {"points", n}});
    out["classes"] = std::move(list);
  }
  return out;
}

void print_json(const ordered_json& doc) {
  std::printf("%s\n", doc.dump(2, ' ', false, nlohmann::json::error_handler_t::replace).c_str());
}

// For a DEM in degrees, WGS 84's UTM zone (its EPSG code) at the centre of its cells;
// otherwise 0. vola convert refuses voxels of degrees and reprojects only points, so such
// a DEM is warped first (or voxelised with --allow-geographic).
int utm_for_dem_in_degrees(const io::Input& in, bool bounded, const Point& lo, const Point& hi) {
  const std::string definition = crs_definition(in.wkt, in.epsg);
  if (!in.terrain || !bounded || definition.empty() || !is_geographic_crs(definition)) return 0;
  const double lon = (lo[0] + hi[0]) / 2, lat = (lo[1] + hi[1]) / 2;
  const int zone = std::clamp(static_cast<int>(std::floor((lon + 180.0) / 6.0)) + 1, 1, 60);
  return (lat >= 0 ? 32600 : 32700) + zone;
}

// The inputs that are not point clouds, by what vola convert makes of them: a mesh's
// triangles, a voxel grid's or map's cells (binvox, NPY occupancy, OctoMap, OpenVDB), a
// height field's cells (DEM: one point per cell with a height). `summary` adds the height
// field's column ranges; a mesh or grid has nothing more to read.
void print_other_input_info(const std::string& path, const io::Input& in, bool summary, bool json,
                            const std::string& part) {
  const char* kind = in.is_mesh() ? "mesh" : in.grid ? "voxel grid" : "height field";
  Point lo{INFINITY, INFINITY, INFINITY}, hi{-INFINITY, -INFINITY, -INFINITY};
  const auto extend = [&](const Point& p) {
    for (std::size_t a = 0; a < 3; ++a) lo[a] = std::min(lo[a], p[a]), hi[a] = std::max(hi[a], p[a]);
  };
  for (const io::Triangle& t : in.triangles)
    for (const Point& p : t) extend(p);
  ordered_json grid;
  if (in.grid) {
    const io::VoxelGrid& g = *in.grid;
    Point far;
    for (std::size_t a = 0; a < 3; ++a) far[a] = g.origin[a] + g.voxel_size * g.dims[a];
    extend(g.origin);
    extend(far);
    ordered_json columns = ordered_json::array();
    for (const auto& a : g.attributes) columns.push_back({{"name", a.name}, {"type", name_of(a.type)}});
    grid = {{"dims", {g.dims[0], g.dims[1], g.dims[2]}},
            {"voxel_size", g.voxel_size},
            {"origin", xyz(g.origin.data())},
            {"occupied", g.voxels.size()},
            {"free", g.free.size() + g.free_cells_dropped},
            {"columns", std::move(columns)},
            {"fixed_voxel_size", g.fixed_voxel_size}};
  }
  if (in.terrain && in.cloud.size() > 0) {
    const Box b = in.cloud.bounds();
    extend(b.min);
    extend(b.max);
  }
  const bool bounded = lo[0] <= hi[0];
  if (json) {
    ordered_json doc = {{"file", path}, {"format", in.format}, {"kind", kind}, {"crs", crs_json(in.wkt, in.epsg)}};
    if (in.is_mesh()) doc["triangles"] = in.triangles.size();
    if (in.grid) doc["grid"] = std::move(grid);
    if (in.terrain) doc["cells"] = in.cloud.size();
    doc["bounds"] = bounded ? ordered_json({{"min", xyz(lo.data())}, {"max", xyz(hi.data())}}) : ordered_json(nullptr);
    if (in.terrain && summary) doc["summary"] = summary_json(summarise(in.cloud));
    print_json(doc);
    return;
  }
  if (in.format == kind)
    std::printf("file:        %s (%s)\n", path.c_str(), kind);
  else
    std::printf("file:        %s (%s, a %s)\n", path.c_str(), in.format.c_str(), kind);
  if (in.is_mesh()) {
    // Mesh readers keep lone vertices (an OBJ of "v" lines alone) as triangles of one point.
    const auto points = static_cast<std::size_t>(std::count_if(
        in.triangles.begin(), in.triangles.end(), [](const io::Triangle& t) { return t[0] == t[1] && t[1] == t[2]; }));
    if (points == in.triangles.size())
      std::printf("points:      %zu (vertices without faces)\n", points);
    else if (points > 0)
      std::printf("triangles:   %zu (%zu of them single points)\n", in.triangles.size(), points);
    else
      std::printf("triangles:   %zu\n", in.triangles.size());
  }
  if (in.grid) {
    const io::VoxelGrid& g = *in.grid;
    std::printf("grid:        %u x %u x %u cells of %.9g, origin (%.9g, %.9g, %.9g)%s\n", g.dims[0], g.dims[1],
                g.dims[2], g.voxel_size, g.origin[0], g.origin[1], g.origin[2],
                g.fixed_voxel_size ? ", the map's own cells" : "");
    std::printf("occupied:    %zu cells\n", g.voxels.size());
    if (!g.free.empty() || g.free_cells_dropped > 0)
      std::printf("free:        %llu cells%s\n", static_cast<unsigned long long>(g.free.size() + g.free_cells_dropped),
                  g.free.empty() ? "" : " (vola convert keeps them: a state map of occupied, free and unknown space)");
    std::printf("columns:    ");
    for (const auto& a : g.attributes) std::printf(" %s (%s)", a.name.c_str(), std::string(name_of(a.type)).c_str());
    std::printf("%s\n", g.attributes.empty() ? " none" : "");
  }
  if (in.terrain) std::printf("cells:       %zu with a height\n", in.cloud.size());
  std::printf("crs:         %s\n", crs_text(crs_definition(in.wkt, in.epsg)).c_str());
  if (bounded)
    std::printf("bounds:      min (%.9g, %.9g, %.9g)\n             max (%.9g, %.9g, %.9g)%s\n", lo[0], lo[1], lo[2],
                hi[0], hi[1], hi[2], in.terrain ? " (cell centres)" : "");
  // A grid's cells are its voxels; the others need a voxel size.
  const int utm = utm_for_dem_in_degrees(in, bounded, lo, hi);
  const std::string grid_option = part.empty() ? "" : " --grid " + part;
  std::printf("to voxels:   vola convert %s OUT.vol%s%s%s\n", path.c_str(), grid_option.c_str(),
              in.grid ? "" : " --voxel-size S", utm ? " --allow-geographic (voxels of degrees)" : "");
  if (utm)
    std::printf("or in metres: gdalwarp -t_srs EPSG:%d %s OUT.tif, then vola convert OUT.tif\n", utm, path.c_str());
  if (in.terrain && summary) print_summary(summarise(in.cloud));
}

}  // namespace

// An E57 file's scans as its XML states them: name, records, pose, fields.
ordered_json e57_json(const io::E57Summary& e) {
  ordered_json scans = ordered_json::array();
  for (const io::E57Scan& s : e.scans) {
    ordered_json pose = nullptr;
    if (s.has_pose)
      pose = {{"rotation_wxyz", {s.rotation[0], s.rotation[1], s.rotation[2], s.rotation[3]}},
              {"translation", {s.translation[0], s.translation[1], s.translation[2]}}};
    scans.push_back({{"name", s.name}, {"records", s.records}, {"pose", pose}, {"fields", s.fields}});
  }
  return {{"version", std::to_string(e.version_major) + "." + std::to_string(e.version_minor)},
          {"library", e.library},
          {"scans", std::move(scans)},
          {"images", e.images}};
}

void print_e57_scans(const io::E57Summary& e) {
  std::printf("e57:         version %u.%u%s%s, %zu scan%s, %llu image%s (not read)\n", e.version_major, e.version_minor,
              e.library.empty() ? "" : ", written by ", e.library.c_str(), e.scans.size(),
              e.scans.size() == 1 ? "" : "s", static_cast<unsigned long long>(e.images), e.images == 1 ? "" : "s");
  for (const io::E57Scan& s : e.scans) {
    std::printf("scan:        '%s': %llu records", s.name.c_str(), static_cast<unsigned long long>(s.records));
    if (s.has_pose)
      std::printf(", pose: rotation (w x y z) %.9g %.9g %.9g %.9g, translation %.9g %.9g %.9g", s.rotation[0],
                  s.rotation[1], s.rotation[2], s.rotation[3], s.translation[0], s.translation[1], s.translation[2]);
    std::printf("\n             fields:");
    for (const auto& f : s.fields) std::printf(" %s", f.c_str());
    std::printf("\n");
  }
}

void print_point_cloud_info(const std::string& path, bool summary, bool json, const std::string& part,
                            const std::string& format_name) {
  io::InputOptions options;
  options.attributes = true;
  options.grid = part;
  if (!part.empty()) {
    const std::string format = io::find_input_format(path, format_name).name;
    if (format != "vdb" && format != "npy")
      throw OptionError("grid", "applies to OpenVDB (.vdb) and NumPy .npz files; " + path + " is " + format);
  }
  const io::Input in = io::read_input(path, format_name, options);
  if (in.is_mesh() || in.grid || in.terrain) return print_other_input_info(path, in, summary, json, part);
  const bool e57 = in.format == "e57";
  // Points with a coordinate that is not finite: the PCD reader leaves them out, the other
  // readers keep them for convert to drop (and count); counted alike here, as convert does.
  // And the points' own bounds: the file was read whole anyway (`--help` promised them;
  // only --summary gave them). One pass for both.
  std::uint64_t not_finite = in.not_finite;
  std::array<double, 3> lo{INFINITY, INFINITY, INFINITY}, hi{-INFINITY, -INFINITY, -INFINITY};
  for (std::size_t i = 0; i < in.cloud.size(); ++i) {
    const double* p = &in.cloud.xyz[3 * i];
    if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2])) {
      ++not_finite;
      continue;
    }
    for (int a = 0; a < 3; ++a) lo[a] = std::min(lo[a], p[a]), hi[a] = std::max(hi[a], p[a]);
  }
  const std::uint64_t points = in.cloud.size() + in.not_finite - not_finite;
  const bool bounded = points > 0 && lo[0] <= hi[0];
  if (json) {
    ordered_json doc = {
        {"file", path},
        {"format", in.format},
        {"points", points},
        {"points_not_finite", not_finite},
        {"crs", crs_json(in.wkt, in.epsg)},
        {"bounds", bounded ? ordered_json({{"min", xyz(lo.data())}, {"max", xyz(hi.data())}}) : ordered_json(nullptr)}};
    ordered_json dimensions = ordered_json::array();
    for (const auto& a : in.cloud.attributes) dimensions.push_back({{"name", a.name}, {"type", name_of(a.type)}});
    doc["dimensions"] = std::move(dimensions);
    if (e57) doc["e57"] = e57_json(io::e57_summary(path));
    if (summary) doc["summary"] = summary_json(summarise(in.cloud));
    print_json(doc);
    return;
  }
  std::printf("file:        %s (%s)\n", path.c_str(), in.format.c_str());
  std::printf("points:      %llu", static_cast<unsigned long long>(points));
  // An organized cloud (PCD) holds its missing points as NaN, an E57 or PTX scan marks
  // them invalid or as 0 0 0: say how many were left out.
  if (not_finite > 0)
    std::printf(e57 || in.format == "ptx" ? " (and %llu the scanner marked as no return or invalid, left out)"
                                          : " (and %llu with a coordinate that is not finite, left out)",
                static_cast<unsigned long long>(not_finite));
  std::printf("\n");
  if (e57) print_e57_scans(io::e57_summary(path));
  std::printf("crs:         %s\n", crs_text(crs_definition(in.wkt, in.epsg)).c_str());
  if (bounded)
    std::printf("bounds:      min %s\n             max %s\n", point_text(lo).c_str(), point_text(hi).c_str());
  std::printf("columns:    ");
  for (const auto& a : in.cloud.attributes)
    std::printf(" %s (%s)", a.name.c_str(), std::string(name_of(a.type)).c_str());
  std::printf("%s\n", in.cloud.attributes.empty() ? " none" : "");
  // Text columns without names are not read: say so rather than let them vanish.
  if (in.format == "text" && in.cloud.attributes.empty()) {
    const int values = io::count_text_columns(path, 0);
    if (values > 3)
      std::printf(
          "             (each line holds %d values: the %d after x y z have no names and are not read; a first "
          "line '# x y z NAME ...', one name a column, names them)\n",
          values, values - 3);
  }
  // So are the columns of a plain (N, K) array after its first three.
  if (in.format == "npy" && in.cloud.attributes.empty() && io::lower_extension(path) == ".npy") {
    const io::NpyArray array = io::read_npy(path);
    if (array.kind != 'V' && array.shape.size() == 2 && array.shape[1] > 3)
      std::printf(
          "             (each row holds %llu values: the %llu after x y z are not read; --nbits 1 reads up to 8 of "
          "them as payload bytes, a structured array keeps its named fields as columns)\n",
          static_cast<unsigned long long>(array.shape[1]), static_cast<unsigned long long>(array.shape[1] - 3));
  }
  if (summary) print_summary(summarise(in.cloud));
}

void print_ept_info(const std::string& path, bool summary, bool json) {
  const io::EptDataset d = io::ept_dataset(path);
  const std::vector<io::EptNode> nodes = io::ept_nodes(path);
  std::map<int, std::pair<std::uint64_t, std::uint64_t>> depths;  // depth -> nodes, points
  std::uint64_t stated = 0;
  for (const io::EptNode& n : nodes) {
    ++depths[n.depth].first;
    depths[n.depth].second += n.points;
    stated += n.points;
  }
  const std::array<double, 6>& box = d.conforming ? *d.conforming : d.bounds;
  std::optional<io::Input> read;
  if (summary) read = io::read_input(path, "ept", {});
  if (json) {
    ordered_json hierarchy = ordered_json::array();
    for (const auto& [depth, counts] : depths)
      hierarchy.push_back({{"depth", depth}, {"nodes", counts.first}, {"points", counts.second}});
    ordered_json dimensions = ordered_json::array();
    for (const auto& name : d.dimensions) dimensions.push_back(name);
    ordered_json doc = {{"file", path},
                        {"format", "EPT"},
                        {"version", d.version},
                        {"data_type", d.data_type},
                        {"points", d.points},
                        {"crs", crs_json(d.wkt, d.epsg)},
                        {"bounds",
                         {{"min", xyz(box.data())},
                          {"max", xyz(box.data() + 3)},
                          {"source", d.conforming ? "boundsConforming" : "bounds"}}},
                        {"dimensions", std::move(dimensions)},
                        {"nodes", nodes.size()},
                        {"hierarchy", std::move(hierarchy)}};
    if (read) doc["summary"] = summary_json(summarise(read->cloud));
    print_json(doc);
    return;
  }
  std::printf("file:        %s (EPT %s, %s)\n", path.c_str(), d.version.empty() ? "?" : d.version.c_str(),
              d.data_type.c_str());
  std::printf("points:      %llu in %zu nodes", static_cast<unsigned long long>(d.points), nodes.size());
  if (stated != d.points) std::printf(" (the hierarchy states %llu)", static_cast<unsigned long long>(stated));
  std::printf("\ncrs:         %s\n", crs_text(crs_definition(d.wkt, d.epsg)).c_str());
  std::printf("bounds:      min (%.9g, %.9g, %.9g)\n             max (%.9g, %.9g, %.9g) (ept.json's %s)\n", box[0],
              box[1], box[2], box[3], box[4], box[5], d.conforming ? "boundsConforming" : "bounds");
  std::printf("dimensions: ");
  for (const auto& name : d.dimensions) std::printf(" %s", name.c_str());
  std::printf("\n");
  for (const auto& [depth, counts] : depths)
    std::printf("depth %-5d  %llu nodes, %llu points\n", depth, static_cast<unsigned long long>(counts.first),
                static_cast<unsigned long long>(counts.second));
  std::printf("to voxels:   vola convert %s OUT.vol --voxel-size S [--level L: depths 0..L only]\n", path.c_str());
  if (read) print_summary(summarise(read->cloud));
}

bool is_point_file(const std::string& path) {
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (!f) return false;
  char magic[4] = {};
  const bool las = std::fread(magic, 1, 4, f) == 4 && std::string(magic, 4) == "LASF";
  std::fclose(f);
  return las;
}

namespace {

// Every dimension of the records (x y z as stored: scaled integers), as PDAL lists them.
ordered_json las_dimensions_json(const io::LasHeader& hd) {
  ordered_json dimensions = ordered_json::array();
  for (const char* axis : {"x", "y", "z"}) dimensions.push_back({{"name", axis}, {"type", "f64"}});
  for (const auto& a : io::las_columns(hd).attributes)
    dimensions.push_back({{"name", a.name}, {"type", name_of(a.type)}});
  return dimensions;
}

void print_las_json(io::LasReader& reader, const std::string& path, bool summary) {
  const io::LasHeader& hd = reader.header();
  ordered_json doc = {
      {"file", path},
      {"format", hd.copc           ? "COPC"
                 : hd.compressed() ? "LAZ"
                                   : "LAS"},
      {"version", hd.version()},
      {"software", hd.generating_software},
      {"system", hd.system_identifier},
      {"points", hd.point_count},
      {"point_format", hd.point_format},
      {"record_length", hd.record_length},
      {"crs", crs_json(hd.wkt, hd.epsg)},
      {"scale", xyz(hd.scale.data())},
      {"offset", xyz(hd.offset.data())},
      {"bounds", {{"min", xyz_at(hd.min.data(), hd)}, {"max", xyz_at(hd.max.data(), hd)}, {"source", "header"}}}};
  doc["dimensions"] = las_dimensions_json(hd);
  ordered_json vlrs = ordered_json::array();
  for (const auto& v : hd.vlrs)
    vlrs.push_back({{"user_id", v.user_id},
                    {"record_id", v.record_id},
                    {"bytes", v.length},
                    {"extended", v.extended},
                    {"description", v.description}});
  doc["vlrs"] = std::move(vlrs);
  if (hd.compressed()) {
    const auto& z = *hd.laszip;
    ordered_json items = ordered_json::array();
    for (const auto& item : z.items) items.push_back(io::laz::describe_item(item));
    doc["laz"] = {{"compressor", z.compressor},
                  {"chunk_size",
                   z.chunk_size == io::laz::kVariableChunkSize ? ordered_json("variable") : ordered_json(z.chunk_size)},
                  {"chunks", hd.laz_chunks.size()},
                  {"items", std::move(items)}};
  }
  if (hd.copc) doc["copc"] = copc_json(*hd.copc);
  if (summary) doc["summary"] = summary_json(summarise_las(reader), &hd);
  print_json(doc);
}

}  // namespace

void print_point_file_info(const std::string& path, bool summary, bool json) {
  io::LasReader reader(path);
  if (json) return print_las_json(reader, path, summary);
  const io::LasHeader& hd = reader.header();
  std::printf("file:        %s (%s %s)\n", path.c_str(),
              hd.copc           ? "COPC"
              : hd.compressed() ? "LAZ"
                                : "LAS",
              hd.version().c_str());
  std::printf("software:    %s%s%s\n", hd.generating_software.c_str(), hd.system_identifier.empty() ? "" : ", system ",
              hd.system_identifier.c_str());
  std::printf("points:      %llu, point format %u, %u bytes a record\n",
              static_cast<unsigned long long>(hd.point_count), hd.point_format, hd.record_length);
  std::printf("crs:         %s\n", crs_text(crs_definition(hd.wkt, hd.epsg)).c_str());
  // As the file holds them, the shortest text that reads back (9 digits made the offset
  // 674521.9200134277 read 674521.92 beside bounds at 674521.920013428).
  const auto exact = [](double v) {
    char text[kNumberTextSize];
    return std::string(text, write_number(text, v));
  };
  std::printf("scale:       %s %s %s, offset %s %s %s\n", exact(hd.scale[0]).c_str(), exact(hd.scale[1]).c_str(),
              exact(hd.scale[2]).c_str(), exact(hd.offset[0]).c_str(), exact(hd.offset[1]).c_str(),
              exact(hd.offset[2]).c_str());
  std::printf("bounds:      min %s\n             max %s (the header's)\n", las_point_text(hd.min.data(), hd).c_str(),
              las_point_text(hd.max.data(), hd).c_str());
  // A CRS label the coordinates cannot fit (lone-star's geocentric keys over UTM metres),
  // as vola convert warns of it: info is where a GIS user looks first.
  if (const std::string definition = crs_definition(hd.wkt, hd.epsg); !definition.empty()) {
    const Box box{{hd.min[0], hd.min[1], hd.min[2]}, {hd.max[0], hd.max[1], hd.max[2]}};
    std::string doubt = implausible_geocentric(definition, box);
    if (doubt.empty()) doubt = implausible_degrees(definition, hd.min[0], hd.min[1], hd.max[0], hd.max[1]);
    if (!doubt.empty()) std::fprintf(stderr, "vola: warning: %s: %s\n", path.c_str(), doubt.c_str());
  }
  std::printf("dimensions:  x y z");
  for (const auto& a : io::las_columns(hd).attributes) std::printf(" %s", a.name.c_str());
  std::printf("\n");
  for (const auto& f : hd.extra_fields) std::printf("extra bytes: %s (type %u)\n", f.name.c_str(), f.data_type);
  for (const auto& v : hd.vlrs)
    std::printf("%s %s:%u, %llu bytes%s%s\n", v.extended ? "evlr:       " : "vlr:        ", v.user_id.c_str(),
                v.record_id, static_cast<unsigned long long>(v.length), v.description.empty() ? "" : ", ",
                v.description.c_str());
  if (hd.compressed()) print_compression(hd);
  if (hd.copc) print_copc(*hd.copc);
  if (summary) print_summary(summarise_las(reader), &hd);
}

}  // namespace vola::cli
