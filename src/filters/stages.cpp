#include "vola/filters/stages.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <numeric>

#include "vola/error.hpp"
#include "vola/filters/dimensions.hpp"
#include "vola/point_selection.hpp"

namespace vola::filters {

namespace {

// A `where` stage came from --where (its expression is what the user typed); the others
// from --filter.
[[noreturn]] void refuse(const std::string& spec, const std::string& cause) {
  if (spec.starts_with("where:")) throw OptionError("where", "'" + spec.substr(6) + "': " + cause);
  throw OptionError("filters", "'" + spec + "': " + cause);
}

double number(const std::string& spec, const std::string& text) {
  double v = 0.0;
  const char* end = text.data() + text.size();
  const auto r = std::from_chars(text.data(), end, v);
  if (r.ec != std::errc() || r.ptr != end || !std::isfinite(v)) refuse(spec, "'" + text + "' is not a number");
  return v;
}

std::vector<std::string> split(const std::string& text, char by) {
  std::vector<std::string> parts;
  std::size_t start = 0;
  for (;;) {
    const auto at = text.find(by, start);
    parts.push_back(text.substr(start, at - start));
    if (at == std::string::npos) return parts;
    start = at + 1;
  }
}

// "name=value,name=value" into the named members.
template <class Set>
void parameters(const std::string& spec, const std::string& args, Set&& set) {
  if (args.empty()) return;
  for (const auto& item : split(args, ',')) {
    const auto eq = item.find('=');
    if (eq == std::string::npos) refuse(spec, "'" + item + "' is not NAME=VALUE");
    set(item.substr(0, eq), number(spec, item.substr(eq + 1)));
  }
}

}  // namespace

Stage parse_stage(const std::string& spec) {
  Stage s;
  s.spec = spec;
  const auto colon = spec.find(':');
  const std::string name = dimension_key(spec.substr(0, colon));
  const std::string args = colon == std::string::npos ? "" : spec.substr(colon + 1);
  try {
    if (name == "where") {
      s.kind = Stage::Kind::where;
      s.expression.emplace(args);
    } else if (name == "smrf") {
      s.kind = Stage::Kind::smrf;
      parameters(spec, args, [&](const std::string& key, double v) {
        if (key == "cell") s.smrf.cell = v;
        else if (key == "slope") s.smrf.slope = v;
        else if (key == "window") s.smrf.window = v;
        else if (key == "threshold") s.smrf.threshold = v;
        else if (key == "scalar") s.smrf.scalar = v;
        else refuse(spec, "smrf has no parameter '" + key + "' (cell, slope, window, threshold, scalar)");
      });
      s.smrf.check();
    } else if (name == "hag") {
      s.kind = Stage::Kind::hag;
      if (!args.empty()) refuse(spec, "hag takes no parameters");
    } else if (name == "outlier") {
      s.kind = Stage::Kind::outlier;
      parameters(spec, args, [&](const std::string& key, double v) {
        if (key == "k" || key == "mean_k") {
          // A count of neighbours: the time grows with it (k = 5000 over 110,000 points took 76 s,
          // k beyond the point count did not end), and statistics over a thousand neighbours
          // are no longer about outliers.
          if (!(v >= 1.0 && v <= OutlierOptions::kMaxNeighbours) || v != std::floor(v))
            refuse(spec, "k must be a whole number from 1 to " + std::to_string(OutlierOptions::kMaxNeighbours) +
                             " (the neighbours of each point whose mean distance is compared; PDAL's default is 8)");
          s.outlier.neighbours = static_cast<int>(v);
        }
        else if (key == "multiplier") s.outlier.multiplier = v;
        else refuse(spec, "outlier has no parameter '" + key + "' (k, multiplier)");
      });
      s.outlier.check();
    } else if (name == "voxel" || name == "poisson") {
      s.kind = name == "voxel" ? Stage::Kind::voxel : Stage::Kind::poisson;
      if (args.empty()) refuse(spec, name + " needs a size: " + name + ":R");
      s.size = number(spec, args);
      if (!(s.size > 0)) refuse(spec, "the size must be positive");
    } else if (name == "crop") {
      s.kind = Stage::Kind::crop;
      const auto parts = split(args, ',');
      std::vector<double> v;
      for (const auto& p : parts) v.push_back(number(spec, p));
      if (v.size() == 4) s.box = {v[0], v[1], v[2], v[3], std::nullopt, std::nullopt};
      else if (v.size() == 6) s.box = {v[0], v[1], v[3], v[4], v[2], v[5]};
      else refuse(spec, "crop takes MINX,MINY,MAXX,MAXY or MINX,MINY,MINZ,MAXX,MAXY,MAXZ");
      if (s.box.min_x > s.box.max_x || s.box.min_y > s.box.max_y || (s.box.min_z && *s.box.min_z > *s.box.max_z))
        refuse(spec, "a minimum is above its maximum");
    } else if (name == "polygon" || name == "croppolygon") {
      s.kind = Stage::Kind::polygon;
      if (args.empty()) refuse(spec, "polygon needs a file: polygon:FILE (GeoJSON or WKT), or the WKT itself");
      std::string head = args.substr(0, 12);
      for (char& ch : head) ch = static_cast<char>(std::toupper(static_cast<unsigned char>(ch)));
      const bool inline_text = args[0] == '{' || head.rfind("POLYGON", 0) == 0 || head.rfind("MULTIPOLYGON", 0) == 0;
      s.polygons = inline_text ? parse_polygons(args, "polygon") : read_polygons(args);
    } else {
      refuse(spec, "no filter '" + spec.substr(0, colon) +
                       "' (where:EXPR, smrf, hag, outlier, voxel:R, poisson:R, crop:..., polygon:FILE)");
    }
  } catch (const OptionError& e) {
    if (e.option() == "filters") throw;
    refuse(spec, e.option() + " " + e.cause());  // a parameter's check: named as in the stage
  } catch (const Error& e) {
    refuse(spec, e.what());
  }
  return s;
}

std::vector<Stage> parse_stages(const std::vector<std::string>& specs) {
  std::vector<Stage> stages;
  for (const auto& spec : specs) stages.push_back(parse_stage(spec));
  return stages;
}

std::vector<bool> per_point_mask(const std::vector<Stage>& stages, const PointCloud& cloud) {
  std::vector<bool> keep(cloud.size(), true);
  for (const Stage& s : stages) {
    std::vector<bool> mask;
    switch (s.kind) {
      case Stage::Kind::where: mask = s.expression->evaluate(cloud); break;
      case Stage::Kind::crop: mask = inside_box(cloud.xyz, s.box); break;
      case Stage::Kind::polygon: mask = inside_polygons(cloud.xyz, s.polygons); break;
      default: throw InvalidArgument("filter '" + s.spec + "' needs all the points at once");
    }
    for (std::size_t i = 0; i < keep.size(); ++i) keep[i] = keep[i] && mask[i];
  }
  return keep;
}

namespace {

// The x/y extent of the finite points (empty when there are none).
struct XyBox {
  double min_x = INFINITY, min_y = INFINITY, max_x = -INFINITY, max_y = -INFINITY;
  bool empty() const { return min_x > max_x; }
};

XyBox xy_box_of(const PointCloud& cloud) {
  XyBox box;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const double x = cloud.xyz[3 * i], y = cloud.xyz[3 * i + 1];
    if (!std::isfinite(x) || !std::isfinite(y)) continue;
    box.min_x = std::min(box.min_x, x), box.max_x = std::max(box.max_x, x);
    box.min_y = std::min(box.min_y, y), box.max_y = std::max(box.max_y, y);
  }
  return box;
}

// A polygon crop that kept nothing because its polygons lie nowhere near the points is a
// polygon in another CRS (GeoJSON in longitude/latitude, as RFC 7946 has it), not an
// empty result: refused, with both extents.
void refuse_polygons_apart(const Stage& s, const XyBox& points) {
  XyBox shapes;
  for (const auto& polygon : s.polygons.polygons)
    for (const auto& ring : polygon)
      for (const auto& [x, y] : ring) {
        shapes.min_x = std::min(shapes.min_x, x), shapes.max_x = std::max(shapes.max_x, x);
        shapes.min_y = std::min(shapes.min_y, y), shapes.max_y = std::max(shapes.max_y, y);
      }
  if (points.empty() || shapes.empty()) return;
  const bool apart = shapes.max_x < points.min_x || shapes.min_x > points.max_x || shapes.max_y < points.min_y ||
                     shapes.min_y > points.max_y;
  if (!apart) return;
  char text[512];
  std::snprintf(text, sizeof text,
                "%s: the polygons (x %.10g..%.10g, y %.10g..%.10g) do not meet the points (x %.10g..%.10g, y "
                "%.10g..%.10g): they are read in the points' CRS, so a polygon in another CRS (GeoJSON in "
                "longitude/latitude) keeps nothing; reproject the polygon first (ogr2ogr -t_srs)",
                s.spec.c_str(), shapes.min_x, shapes.max_x, shapes.min_y, shapes.max_y, points.min_x, points.max_x,
                points.min_y, points.max_y);
  throw InvalidArgument(text);
}

}  // namespace

FilterResult run_stages(const std::vector<Stage>& stages, PointCloud& cloud, const std::optional<std::uint32_t>& epsg,
                        const std::string& wkt, std::uint64_t first_index) {
  const XyBox cloud_box = xy_box_of(cloud);  // before the stages: what a crop could meet
  FilterResult result;
  result.kept.resize(cloud.size());
  std::iota(result.kept.begin(), result.kept.end(), first_index);
  std::optional<Units> units;
  for (const Stage& s : stages) {
    StageReport report{s.spec, cloud.size(), 0, 0};
    std::vector<bool> keep;
    switch (s.kind) {
      case Stage::Kind::where:
      case Stage::Kind::crop:
      case Stage::Kind::polygon: keep = per_point_mask({s}, cloud); break;
      case Stage::Kind::smrf:
        if (!units) units = units_of_crs(epsg, wkt);
        report.ground = classify_ground(cloud, s.smrf, *units);
        break;
      case Stage::Kind::hag: add_height_above_ground(cloud); break;
      case Stage::Kind::outlier: {
        keep = statistical_outliers(cloud.xyz, s.outlier);
        keep.flip();
        break;
      }
      case Stage::Kind::voxel: keep = voxel_decimation(cloud.xyz, s.size); break;
      case Stage::Kind::poisson: keep = poisson_decimation(cloud.xyz, s.size); break;
    }
    if (!keep.empty()) {
      keep_points(cloud, keep);
      std::size_t out = 0;
      for (std::size_t i = 0; i < keep.size(); ++i)
        if (keep[i]) result.kept[out++] = result.kept[i];
      result.kept.resize(out);
    }
    report.points_out = cloud.size();
    if (s.kind == Stage::Kind::polygon && report.points_in > 0 && report.points_out == 0)
      refuse_polygons_apart(s, cloud_box);
    result.stages.push_back(report);
  }
  return result;
}

}  // namespace vola::filters
