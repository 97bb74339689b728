#include "vola/filters/smrf.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <span>

#include "elevation_grid.hpp"
#include "vola/error.hpp"
#include "vola/filters/dimensions.hpp"
#include "vola/filters/kd_tree.hpp"
#include "vola/parallel.hpp"

namespace vola::filters {

using detail::ElevationGrid;

void SmrfOptions::check() const {
  const auto positive = [](const char* name, double v) {
    if (!(v > 0.0) || !std::isfinite(v))
      throw OptionError(name, "must be a positive number (metres), not " + std::to_string(v));
  };
  positive("cell", cell);
  positive("window", window);
  // Radii in cells become ints: a window of more than 100000 cells (or cells under a
  // millimetre) is a typo, not a survey.
  if (cell < 1e-3) throw OptionError("cell", "must be at least 0.001 m, not " + std::to_string(cell));
  if (window / cell > 1e5) throw OptionError("window", "is more than 100000 cells of " + std::to_string(cell) + " m");
  if (!(slope >= 0.0) || !std::isfinite(slope)) throw OptionError("slope", "must be 0 or more");
  if (!(threshold >= 0.0) || !std::isfinite(threshold)) throw OptionError("threshold", "must be 0 or more");
  if (!(scalar >= 0.0) || !std::isfinite(scalar)) throw OptionError("scalar", "must be 0 or more");
}

namespace {

constexpr double kMaxCells = double(1u << 28);

// Cells an opening lowers by more than slope x radius x cell, for radius 1..max_radius
// (each opening of the previous surface: openings by growing disks, the progressive filter).
std::vector<bool> progressive_objects(const ElevationGrid& surface, int max_radius, double slope) {
  std::vector<bool> object(surface.cells(), false);
  ElevationGrid previous = surface, opened;
  for (int r = 1; r <= max_radius; ++r) {
    detail::open_disk(previous, opened, r);
    const double limit = slope * r * surface.cell;
    for (std::size_t i = 0; i < surface.cells(); ++i)
      if (previous.z[i] - opened.z[i] > limit) object[i] = true;
    std::swap(previous, opened);
  }
  return object;
}

// Heights of a cell's neighbours and their distances (metres) from it.
struct Neighbour {
  double distance;
  float z;
};

// A cell at height z is an unsupported low when some neighbour lies more than
// kPitDepth + kPitSlope x distance above it and fewer than kMinSupport lie within that
// height of it: nothing continues it, as ground continues ground, even in a forest where
// only some cells see it.
bool unsupported(float z, std::span<const Neighbour> near) {
  constexpr int kMinSupport = 2;
  int support = 0;
  bool below_some = false;
  for (const Neighbour& n : near) {
    const double reach = kPitDepth + kPitSlope * n.distance;
    if (std::abs(n.z - z) <= reach) ++support;
    if (n.z - z > reach) below_some = true;
  }
  return below_some && support < kMinSupport;
}

// The filled cells within `radius` cells of cell (i, j), but itself.
void neighbours_within(const ElevationGrid& g, std::ptrdiff_t i, std::ptrdiff_t j, std::ptrdiff_t r,
                       std::vector<Neighbour>& near) {
  const auto cols = static_cast<std::ptrdiff_t>(g.cols), rows = static_cast<std::ptrdiff_t>(g.rows);
  near.clear();
  for (std::ptrdiff_t jj = std::max<std::ptrdiff_t>(0, j - r); jj <= std::min(rows - 1, j + r); ++jj)
    for (std::ptrdiff_t ii = std::max<std::ptrdiff_t>(0, i - r); ii <= std::min(cols - 1, i + r); ++ii) {
      const float w = g.z[static_cast<std::size_t>(jj * cols + ii)];
      if ((ii == i && jj == j) || std::isnan(w)) continue;
      near.push_back({std::hypot(static_cast<double>(ii - i), static_cast<double>(jj - j)) * g.cell, w});
    }
}

// The filled cells' centres (in cells) and their indices, for nearest-cell queries.
struct FilledCells {
  std::vector<double> centres;  // x y pairs
  std::vector<std::size_t> index;
  explicit FilledCells(const ElevationGrid& g) {
    for (std::size_t k = 0; k < g.cells(); ++k)
      if (!std::isnan(g.z[k])) {
        centres.push_back(static_cast<double>(k % g.cols));
        centres.push_back(static_cast<double>(k / g.cols));
        index.push_back(k);
      }
  }
};

// Cells whose minimum no other cell nearby continues (unsupported(), over the cells
// within `radius` cells) while some cell nearby lies far above it: low outliers that come
// in scattered clusters at random depths (multipath echoes under glass and water), which
// the opening below tolerates once they span a few cells. Where fewer than
// kSparseNeighbours cells lie within the radius (a thinned survey, the edge of the data,
// an echo out in a void), the neighbourhood grows to the kSparseNeighbours nearest filled
// cells, whatever their distance: the reach grows with the distance, so sparse ground is
// still continued by its neighbours, while an echo tens of metres below the data a few
// metres away is not.
std::vector<bool> unsupported_lows(const ElevationGrid& g, int radius) {
  const auto r = static_cast<std::ptrdiff_t>(radius);
  const auto cols = static_cast<std::ptrdiff_t>(g.cols);
  // Rows in parallel: each writes only its own cells (vectors of char, not vector<bool>,
  // whose bits share words). 2 marks a cell with too few neighbours in the radius.
  constexpr char kSparse = 2;
  std::vector<char> low_rows(g.cells(), 0);
  parallel_for(g.rows, [&](std::size_t first, std::size_t last) {
    std::vector<Neighbour> near;
    for (auto j = static_cast<std::ptrdiff_t>(first); j < static_cast<std::ptrdiff_t>(last); ++j)
      for (std::ptrdiff_t i = 0; i < cols; ++i) {
        const auto k = static_cast<std::size_t>(j * cols + i);
        if (std::isnan(g.z[k])) continue;
        neighbours_within(g, i, j, r, near);
        low_rows[k] = near.size() < kSparseNeighbours ? kSparse : unsupported(g.z[k], near);
      }
  });
  std::vector<std::size_t> sparse;
  for (std::size_t k = 0; k < g.cells(); ++k)
    if (low_rows[k] == kSparse) sparse.push_back(k);
  if (!sparse.empty()) {
    const FilledCells filled(g);
    const KdTree<2> tree(filled.centres, 2);
    parallel_for(sparse.size(), [&](std::size_t first, std::size_t last) {
      std::vector<Neighbour> near;
      for (std::size_t s = first; s < last; ++s) {
        const std::size_t k = sparse[s];
        near.clear();
        const std::array<double, 2> centre{static_cast<double>(k % g.cols), static_cast<double>(k / g.cols)};
        for (const auto& [d2, id] : tree.nearest(centre, kSparseNeighbours + 1))
          if (filled.index[id] != k) near.push_back({std::sqrt(d2) * g.cell, g.z[filled.index[id]]});
        low_rows[k] = unsupported(g.z[k], near);
      }
    });
  }
  std::vector<bool> low(low_rows.begin(), low_rows.end());
  return low;
}

// Gradient magnitude (rise over run) of a filled grid, central differences inside.
std::vector<float> slope_of(const ElevationGrid& g) {
  std::vector<float> s(g.cells());
  for (std::size_t j = 0; j < g.rows; ++j)
    for (std::size_t i = 0; i < g.cols; ++i) {
      const std::size_t il = i > 0 ? i - 1 : i, ir = i + 1 < g.cols ? i + 1 : i;
      const std::size_t jl = j > 0 ? j - 1 : j, jr = j + 1 < g.rows ? j + 1 : j;
      const double gx = ir > il ? (g.at(ir, j) - g.at(il, j)) / (static_cast<double>(ir - il) * g.cell) : 0.0;
      const double gy = jr > jl ? (g.at(i, jr) - g.at(i, jl)) / (static_cast<double>(jr - jl) * g.cell) : 0.0;
      s[j * g.cols + i] = static_cast<float>(std::sqrt(gx * gx + gy * gy));
    }
  return s;
}

}  // namespace

std::vector<bool> smrf_ground(std::span<const double> xyz, const std::vector<bool>& candidate,
                              const SmrfOptions& options, const Units& units) {
  options.check();
  const std::size_t n = xyz.size() / 3;
  std::vector<bool> ground(n, false);
  // Everything below is in metres.
  const double h = units.horizontal, v = units.vertical;
  double minx = INFINITY, miny = INFINITY, maxx = -INFINITY, maxy = -INFINITY;
  std::size_t candidates = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (!candidate[i] || !std::isfinite(xyz[3 * i]) || !std::isfinite(xyz[3 * i + 1]) || !std::isfinite(xyz[3 * i + 2]))
      continue;
    minx = std::min(minx, xyz[3 * i] * h), maxx = std::max(maxx, xyz[3 * i] * h);
    miny = std::min(miny, xyz[3 * i + 1] * h), maxy = std::max(maxy, xyz[3 * i + 1] * h);
    ++candidates;
  }
  if (candidates == 0) return ground;
  const double c = options.cell;
  const double cols_d = std::floor((maxx - minx) / c) + 1, rows_d = std::floor((maxy - miny) / c) + 1;
  if (cols_d * rows_d > kMaxCells)
    throw InvalidArgument("smrf: a grid of " + std::to_string(cols_d) + " x " + std::to_string(rows_d) + " cells of " +
                          std::to_string(c) + " m is too large; give a larger cell or crop first");
  ElevationGrid zmin(static_cast<std::size_t>(cols_d), static_cast<std::size_t>(rows_d), minx, miny, c);
  const auto cell_of = [&](std::size_t i) {
    const auto col = std::min(zmin.cols - 1, static_cast<std::size_t>((xyz[3 * i] * h - minx) / c));
    const auto row = std::min(zmin.rows - 1, static_cast<std::size_t>((xyz[3 * i + 1] * h - miny) / c));
    return row * zmin.cols + col;
  };
  for (std::size_t i = 0; i < n; ++i) {
    if (!candidate[i] || !std::isfinite(xyz[3 * i]) || !std::isfinite(xyz[3 * i + 1]) || !std::isfinite(xyz[3 * i + 2]))
      continue;
    float& cell = zmin.z[cell_of(i)];
    const auto z = static_cast<float>(xyz[3 * i + 2] * v);
    if (std::isnan(cell) || z < cell) cell = z;
  }

  // Low outliers: cells below their neighbours that no neighbour continues (repeated, as
  // removing one can leave another without support), then pits of the minimum surface
  // found as peaks of its negation.
  const int support_radius = std::max(1, static_cast<int>(std::lround(kSupportRadius / c)));
  for (int pass = 0; pass < kSupportPasses; ++pass) {
    const std::vector<bool> low = unsupported_lows(zmin, support_radius);
    if (std::find(low.begin(), low.end(), true) == low.end()) break;
    for (std::size_t k = 0; k < zmin.cells(); ++k)
      if (low[k]) zmin.z[k] = NAN;
  }
  ElevationGrid negated = zmin;
  for (float& z : negated.z) z = -z;
  detail::inpaint(negated);
  const int low_radius = std::max(1, static_cast<int>(std::ceil(kLowOutlierWindow / c)));
  const std::vector<bool> pit = progressive_objects(negated, low_radius, kLowOutlierSlope);
  for (std::size_t k = 0; k < zmin.cells(); ++k)
    if (pit[k]) zmin.z[k] = NAN;

  ElevationGrid filled = zmin;
  detail::inpaint(filled);
  const int max_radius = std::max(1, static_cast<int>(std::ceil(options.window / c)));
  const std::vector<bool> object = progressive_objects(filled, max_radius, options.slope);

  ElevationGrid surface = zmin;
  for (std::size_t k = 0; k < surface.cells(); ++k)
    if (object[k]) surface.z[k] = NAN;
  detail::inpaint(surface);
  const std::vector<float> slope = slope_of(surface);

  for (std::size_t i = 0; i < n; ++i) {
    if (!candidate[i] || !std::isfinite(xyz[3 * i]) || !std::isfinite(xyz[3 * i + 1]) || !std::isfinite(xyz[3 * i + 2]))
      continue;
    const double ground_z = detail::interpolate(surface, xyz[3 * i] * h, xyz[3 * i + 1] * h);
    const double limit = options.threshold + options.scalar * slope[cell_of(i)];
    ground[i] = std::abs(xyz[3 * i + 2] * v - ground_z) <= limit;
  }
  return ground;
}

std::size_t classify_ground(PointCloud& cloud, const SmrfOptions& options, const Units& units) {
  const std::size_t n = cloud.size();
  const std::size_t cls = ensure_column(cloud, "classification", ValueType::u8, Reduction::majority);
  const auto returns = find_dimension(cloud, "return_number");
  const auto count = find_dimension(cloud, "number_of_returns");
  std::vector<bool> candidate(n, true);
  const auto& classes = cloud.attributes[cls].values;
  for (std::size_t i = 0; i < n; ++i) {
    if (classes[i] == 7 || classes[i] == 18) candidate[i] = false;
    // Last or only returns (files without return numbers, or with 0, count as single).
    if (options.last_returns_only && returns && count && returns->axis < 0 && count->axis < 0) {
      const double r = value_of(cloud, *returns, i), m = value_of(cloud, *count, i);
      if (m > 0 && r < m) candidate[i] = false;
    }
  }
  const std::vector<bool> ground = smrf_ground(cloud.xyz, candidate, options, units);
  auto& values = cloud.attributes[cls].values;
  std::size_t found = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (values[i] == 7 || values[i] == 18) continue;
    values[i] = ground[i] ? 2.0 : 1.0;
    found += ground[i];
  }
  return found;
}

}  // namespace vola::filters
