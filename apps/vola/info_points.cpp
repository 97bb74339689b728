// vola info on a LAS, LAZ or COPC file: what the header, the (E)VLRs, the compression and
// the COPC octree say, read without decoding a point.
#include "info_points.hpp"

#include <algorithm>
#include <cstdio>
#include <map>
#include <string>

#include "vola/error.hpp"
#include "vola/geo/crs.hpp"
#include "vola/analysis/census.hpp"
#include "vola/io/input.hpp"
#include "vola/io/las.hpp"

namespace vola::cli {

namespace {

std::string crs_of(const io::LasHeader& hd) {
  const std::string definition = !hd.wkt.empty() ? hd.wkt : hd.epsg ? "EPSG:" + std::to_string(*hd.epsg) : "";
  if (definition.empty()) return "none stated";
  try {
    return geo::crs_summary(geo::describe_crs(definition));
  } catch (const Error& e) {
    return "not readable by PROJ (" + std::string(e.what()) + ")";
  }
}

void print_compression(const io::LasHeader& hd) {
  const auto& z = *hd.laszip;
  const char* kinds[] = {"none", "point-wise", "point-wise chunked", "layered chunked"};
  std::printf("laz:         compressor %u (%s), LASzip %u.%u r%u, ", z.compressor, z.compressor <= 3 ? kinds[z.compressor] : "?",
              z.version_major, z.version_minor, z.revision);
  if (z.chunk_size == io::laz::kVariableChunkSize) std::printf("variable chunks");
  else std::printf("chunks of %u points", z.chunk_size);
  std::printf(", %zu chunks\nitems:      ", hd.laz_chunks.size());
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
  std::printf("copc:        octree of %d levels, %zu nodes with points (%llu points), %zu hierarchy pages\n", copc.levels,
              copc.nodes.size(), static_cast<unsigned long long>(points), copc.pages);
  std::printf("             cube centre (%.9g, %.9g, %.9g), half size %.9g, root spacing %.9g\n", i.center[0], i.center[1],
              i.center[2], i.halfsize, i.spacing);
  for (std::size_t l = 0; l < per_level.size(); ++l)
    std::printf("             level %zu: %zu nodes, %llu points, spacing %.6g\n", l, nodes_per_level[l],
                static_cast<unsigned long long>(per_level[l]), i.spacing / static_cast<double>(std::uint64_t{1} << l));
}

// The column named `name`, or nullptr.
const PointAttribute* column_named(const PointCloud& cloud, const std::string& name) {
  for (const auto& a : cloud.attributes)
    if (a.name == name) return &a;
  return nullptr;
}

// Every point read: the count, the points' own bounds, each column's range and, for a
// classification column, the count per class with ASPRS's names (as pdal info
// --summary reports them).
void print_summary(const PointCloud& cloud) {
  const Box box = cloud.bounds();
  std::printf("summary:     %zu points read\n", cloud.size());
  std::printf("             min (%.9g, %.9g, %.9g)\n             max (%.9g, %.9g, %.9g) (the points')\n", box.min[0],
              box.min[1], box.min[2], box.max[0], box.max[1], box.max[2]);
  for (const auto& a : cloud.attributes) {
    if (a.values.empty()) continue;
    const auto [lo, hi] = std::minmax_element(a.values.begin(), a.values.end());
    std::printf("column:      %s: %.9g .. %.9g\n", a.name.c_str(), *lo, *hi);
  }
  if (const PointAttribute* classes = column_named(cloud, "classification")) {
    std::map<int, std::uint64_t> counts;
    for (const double c : classes->values) ++counts[static_cast<int>(c)];
    for (const auto& [code, n] : counts)
      std::printf("class:       %3d %-38s %llu\n", code, std::string(analysis::asprs_class_name(code)).c_str(),
                  static_cast<unsigned long long>(n));
  }
}

}  // namespace

void print_point_cloud_info(const std::string& path, bool summary) {
  io::InputOptions options;
  options.attributes = true;
  const io::Input in = io::read_input(path, "auto", options);
  if (in.is_mesh() || in.grid || in.terrain)
    throw InvalidArgument(path + ": vola info describes .vol and point files; this is " + in.format +
                          " input (convert it with vola convert, then vola info the .vol)");
  std::printf("file:        %s (%s)\n", path.c_str(), in.format.c_str());
  std::printf("points:      %zu\n", in.cloud.size());
  const std::string definition = !in.wkt.empty() ? in.wkt : in.epsg ? "EPSG:" + std::to_string(*in.epsg) : "";
  std::string crs = "none stated";
  if (!definition.empty()) {
    try {
      crs = geo::crs_summary(geo::describe_crs(definition));
    } catch (const Error& e) {
      crs = "not readable by PROJ (" + std::string(e.what()) + ")";
    }
  }
  std::printf("crs:         %s\n", crs.c_str());
  std::printf("columns:    ");
  for (const auto& a : in.cloud.attributes) std::printf(" %s (%s)", a.name.c_str(), std::string(name_of(a.type)).c_str());
  std::printf("%s\n", in.cloud.attributes.empty() ? " none" : "");
  if (summary) print_summary(in.cloud);
}

bool is_point_file(const std::string& path) {
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (!f) return false;
  char magic[4] = {};
  const bool las = std::fread(magic, 1, 4, f) == 4 && std::string(magic, 4) == "LASF";
  std::fclose(f);
  return las;
}

void print_point_file_info(const std::string& path, bool summary) {
  io::LasReader reader(path);
  const io::LasHeader& hd = reader.header();
  std::printf("file:        %s (%s %s)\n", path.c_str(), hd.copc ? "COPC" : hd.compressed() ? "LAZ" : "LAS",
              hd.version().c_str());
  std::printf("software:    %s%s%s\n", hd.generating_software.c_str(), hd.system_identifier.empty() ? "" : ", system ",
              hd.system_identifier.c_str());
  std::printf("points:      %llu, point format %u, %u bytes a record\n", static_cast<unsigned long long>(hd.point_count),
              hd.point_format, hd.record_length);
  std::printf("crs:         %s\n", crs_of(hd).c_str());
  std::printf("scale:       %.9g %.9g %.9g, offset %.9g %.9g %.9g\n", hd.scale[0], hd.scale[1], hd.scale[2], hd.offset[0],
              hd.offset[1], hd.offset[2]);
  std::printf("bounds:      min (%.9g, %.9g, %.9g)\n             max (%.9g, %.9g, %.9g) (the header's)\n", hd.min[0],
              hd.min[1], hd.min[2], hd.max[0], hd.max[1], hd.max[2]);
  for (const auto& f : hd.extra_fields) std::printf("extra bytes: %s (type %u)\n", f.name.c_str(), f.data_type);
  for (const auto& v : hd.vlrs)
    std::printf("%s %s:%u, %llu bytes%s%s\n", v.extended ? "evlr:       " : "vlr:        ", v.user_id.c_str(),
                v.record_id, static_cast<unsigned long long>(v.length), v.description.empty() ? "" : ", ",
                v.description.c_str());
  if (hd.compressed()) print_compression(hd);
  if (hd.copc) print_copc(*hd.copc);
  if (summary) print_summary(io::las_points(reader, true, false));
}

}  // namespace vola::cli
