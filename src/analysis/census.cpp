#include "vola/analysis/census.hpp"

#include <algorithm>
#include <cmath>
#include <map>

#include "vola/error.hpp"

namespace vola::analysis {

std::string_view asprs_class_name(int code, int las_minor) noexcept {
  if (las_minor < 4) {
    static constexpr std::string_view kLegacy[] = {"Created, never classified",
                                                   "Unclassified",
                                                   "Ground",
                                                   "Low Vegetation",
                                                   "Medium Vegetation",
                                                   "High Vegetation",
                                                   "Building",
                                                   "Low Point (noise)",
                                                   "Model Key-point (mass point)",
                                                   "Water",
                                                   "Reserved",
                                                   "Reserved",
                                                   "Overlap Points"};
    if (code >= 0 && code <= 12) return kLegacy[code];
    if (code >= 13 && code <= 31) return "Reserved";
    return "Not an ASPRS class";  // 5 bits
  }
  static constexpr std::string_view kNames[] = {
      "Created, never classified", "Unclassified", "Ground", "Low Vegetation", "Medium Vegetation",
      "High Vegetation", "Building", "Low Point (noise)", "Reserved", "Water", "Rail", "Road Surface", "Reserved",
      "Wire - Guard (Shield)", "Wire - Conductor (Phase)", "Transmission Tower", "Wire-Structure Connector (Insulator)",
      "Bridge Deck", "High Noise"};
  if (code >= 0 && code <= 18) return kNames[code];
  if (code >= 19 && code <= 63) return "Reserved";
  if (code >= 64 && code <= 255) return "User definable";
  return "Not an ASPRS class";
}

namespace {

// Two passes over `values(i)` for i < n: range, then bins. NaN (a voxel without a value)
// is left out of both.
template <class Values>
Histogram histogram(std::uint64_t n, int bins, Values values) {
  Histogram h;
  h.counts.assign(static_cast<std::size_t>(bins), 0);
  h.min = INFINITY;
  h.max = -INFINITY;
  for (std::uint64_t i = 0; i < n; ++i) {
    const double v = values(i);
    if (std::isnan(v)) continue;
    h.min = std::min(h.min, v);
    h.max = std::max(h.max, v);
  }
  if (h.min > h.max) {  // no value at all
    h.min = h.max = 0.0;
    return h;
  }
  const double width = (h.max - h.min) / bins;
  for (std::uint64_t i = 0; i < n; ++i) {
    const double v = values(i);
    if (std::isnan(v)) continue;
    auto bin = width > 0 ? static_cast<std::int64_t>((v - h.min) / width) : 0;
    bin = std::clamp<std::int64_t>(bin, 0, bins - 1);
    ++h.counts[static_cast<std::size_t>(bin)];
  }
  return h;
}

bool in_polygon(const std::vector<std::array<double, 2>>& poly, double x, double y) noexcept {
  bool inside = false;
  for (std::size_t i = 0, j = poly.size() - 1; i < poly.size(); j = i++) {
    const auto& a = poly[i];
    const auto& b = poly[j];
    if ((a[1] > y) != (b[1] > y) && x < (b[0] - a[0]) * (y - a[1]) / (b[1] - a[1]) + a[0]) inside = !inside;
  }
  return inside;
}

bool in_region(const Region& r, const Point& p) noexcept {
  if (r.box) {
    for (int a = 0; a < 3; ++a)
      if (p[a] < r.box->min[a] || p[a] > r.box->max[a]) return false;
    return true;
  }
  return in_polygon(r.polygon, p[0], p[1]);
}

}  // namespace

Census take_census(const Tree& tree, const CensusOptions& options) {
  if (options.bins < 1) throw InvalidArgument("census: at least one histogram bin");
  for (const Region& r : options.regions)
    if (!r.box && r.polygon.size() < 3) throw InvalidArgument("census: region '" + r.label + "' needs a box or a polygon of 3+ points");
  Census c;
  c.depth = tree.depth();
  c.voxels = tree.voxel_count();
  for (int l = 0; l < tree.depth(); ++l) {
    LevelCensus level;
    level.blocks = tree.occupancy(l).size();
    level.cells = tree.node_count(l);
    level.fill = level.blocks ? static_cast<double>(level.cells) / (64.0 * static_cast<double>(level.blocks)) : 0.0;
    c.levels.push_back(level);
  }
  if (tree.stored_frame() && tree.stored_frame()->quantization == Quantization::grid)
    c.voxel_size = tree.stored_frame()->voxel_size;

  const Quantizer q = tree.quantizer();
  std::vector<std::uint64_t> columns;
  std::vector<double> z;
  columns.reserve(static_cast<std::size_t>(c.voxels));
  z.reserve(static_cast<std::size_t>(c.voxels));
  c.region_voxels.assign(options.regions.size(), 0);
  tree.for_each_voxel([&](const Voxel& v) {
    columns.push_back(std::uint64_t{v.x} | (std::uint64_t{v.y} << 32));
    const Point p = q.center(v);
    z.push_back(p[2]);
    for (std::size_t i = 0; i < options.regions.size(); ++i)
      if (in_region(options.regions[i], p)) ++c.region_voxels[i];
  });
  std::sort(columns.begin(), columns.end());
  c.columns = static_cast<std::uint64_t>(std::unique(columns.begin(), columns.end()) - columns.begin());
  columns = {};
  c.heights = histogram(z.size(), options.bins, [&](std::uint64_t i) { return z[i]; });
  z = {};

  for (const AttributeColumn& column : tree.attributes().columns()) {
    AttributeCensus a;
    a.name = column.name();
    double sum = 0;
    for (std::size_t i = 0; i < column.size(); ++i) {
      const double v = column.get(i);
      if (std::isnan(v))
        ++a.without_value;
      else
        sum += v;
    }
    a.count = column.size() - a.without_value;
    a.mean = a.count ? sum / static_cast<double>(a.count) : 0.0;
    a.histogram = histogram(column.size(), options.bins,
                            [&](std::uint64_t i) { return column.get(static_cast<std::size_t>(i)); });
    if (column.name() == "classification") {
      std::map<int, std::uint64_t> counts;
      for (std::size_t i = 0; i < column.size(); ++i)
        if (const double v = column.get(i); !std::isnan(v)) ++counts[static_cast<int>(v)];
      for (const auto& [code, n] : counts) a.classes.push_back({code, n});
    }
    c.attributes.push_back(std::move(a));
  }
  return c;
}

}  // namespace vola::analysis
