#include "vola/filters/smrf.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <span>
#include <string>

#include <unistd.h>

#include "elevation_grid.hpp"
#include "vola/error.hpp"
#include "vola/filters/dimensions.hpp"
#include "vola/filters/kd_tree.hpp"
#include "vola/parallel.hpp"

namespace vola::filters {

using detail::ElevationGrid;

void SmrfOptions::check() const {
  const auto text = [](double v) {
    char out[32];
    std::snprintf(out, sizeof out, "%g", v);
    return std::string(out);
  };
  const auto positive = [&](const char* name, double v) {
    if (!(v > 0.0) || !std::isfinite(v)) throw OptionError(name, "must be a positive number (metres), not " + text(v));
  };
  positive("cell", cell);
  positive("window", window);
  // Radii in cells become ints: a window of more than 100000 cells (or cells under a
  // millimetre) is a typo, not a survey.
  if (cell < 1e-3) throw OptionError("cell", "must be at least 0.001 m, not " + text(cell));
  if (window / cell > 1e5) throw OptionError("window", "is more than 100000 cells of " + text(cell) + " m");
  if (!(slope >= 0.0) || !std::isfinite(slope)) throw OptionError("slope", "must be 0 or more");
  if (!(threshold >= 0.0) || !std::isfinite(threshold)) throw OptionError("threshold", "must be 0 or more");
  if (!(scalar >= 0.0) || !std::isfinite(scalar)) throw OptionError("scalar", "must be 0 or more");
}

namespace {

constexpr double kMaxCells = double(1u << 28);
// Bytes the grids take per cell: the minimum surface, its fills and openings, the plateau
// step's patches (measured: 5.0 GB for 8001 x 8001 cells of three points).
constexpr double kBytesPerCell = 80.0;

// The grid memory SMRF may take: half of this machine's.
double grid_memory_budget() {
  const long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGE_SIZE);
  return pages > 0 && page > 0 ? 0.5 * static_cast<double>(pages) * static_cast<double>(page) : 8e9;
}

std::string gigabytes(double bytes) {
  char out[32];
  std::snprintf(out, sizeof out, bytes < 1e15 ? "%.1f GB" : "%.3g GB", bytes / 1e9);
  return out;
}

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

// Gradient magnitude (rise over run) of a filled grid: central differences between the
// cells `reach` cells to each side (fewer at the edges). The paper takes neighbouring
// cells; over a surface of cell minima that measures the roughness of the ground cover as
// much as the terrain's slope, and the tolerance it feeds then lets low vegetation on
// slopes pass for ground (kSlopeBaseline, docs/FILTERS.md).
std::vector<float> slope_of(const ElevationGrid& g, std::size_t reach) {
  std::vector<float> s(g.cells());
  for (std::size_t j = 0; j < g.rows; ++j)
    for (std::size_t i = 0; i < g.cols; ++i) {
      const std::size_t il = i >= reach ? i - reach : 0, ir = std::min(g.cols - 1, i + reach);
      const std::size_t jl = j >= reach ? j - reach : 0, jr = std::min(g.rows - 1, j + reach);
      const double gx = ir > il ? (g.at(ir, j) - g.at(il, j)) / (static_cast<double>(ir - il) * g.cell) : 0.0;
      const double gy = jr > jl ? (g.at(i, jr) - g.at(i, jl)) / (static_cast<double>(jr - jl) * g.cell) : 0.0;
      s[j * g.cols + i] = static_cast<float>(std::sqrt(gx * gx + gy * gy));
    }
  return s;
}

// Ground cells on a raised plateau: patches of the ground surface left after the
// opening that stand on walls above the ground beside them. The opening removes what its
// window spans; a roof wider than the window (a warehouse, a survey clipped to one
// building) survives it as a flat patch. Measured cells (NaN elsewhere) that see each
// other across at most kLinkRadius of empty cells join one patch when they rise by at
// most kLinkRise + kLinkSlope x distance, as terrain does; two such cells of different
// patches form a wall. A patch is raised when:
//  - it is the upper side of most of its wall pairs with patches of at least
//    kMinBaseArea that it does not enclose (ground is what roofs stand on; a pit or an
//    excavation inside the ground, within its bounding box, does not raise the ground);
//  - its heights span less than its walls rise on average (a roof is flat; a steep
//    hillside cut into patches by voids spans more than its steps).
// What it cannot tell from a roof: flat ground on top of a retaining wall or a quay more
// than kLinkRise + 0.5 m high, with no higher ground beside it (docs/FILTERS.md).
std::vector<bool> raised_plateaus(const ElevationGrid& g) {
  const std::size_t cols = g.cols, rows = g.rows, cells = g.cells();
  const double c = g.cell;
  const double reach = std::max(kLinkRadius, c);
  const auto gentle = [&](float a, float b, double distance) {
    return std::abs(double{a} - double{b}) <= kLinkRise + kLinkSlope * distance;
  };
  // Union-find over measured cells.
  std::vector<std::uint32_t> parent(cells);
  for (std::size_t k = 0; k < cells; ++k) parent[k] = static_cast<std::uint32_t>(k);
  const auto root = [&](std::size_t k) {
    while (parent[k] != k) k = parent[k] = parent[parent[k]];
    return k;
  };
  // Pairs of measured cells that see each other across empty cells: from every measured
  // cell, the first measured cell along each of 8 directions (half of 16, so that each
  // pair comes once), up to the reach. A void (a building's shadow, a removed object) is
  // crossed; dense data pairs each cell with its neighbours only.
  static constexpr int kDirections[8][2] = {{1, 0}, {2, 1}, {1, 1}, {1, 2}, {0, 1}, {-1, 2}, {-1, 1}, {-2, 1}};
  const auto for_each_pair = [&](auto&& visit) {
    for (std::size_t row = 0; row < rows; ++row)
      for (std::size_t col = 0; col < cols; ++col) {
        const std::size_t a = row * cols + col;
        if (std::isnan(g.z[a])) continue;
        for (const auto& [dx, dy] : kDirections) {
          const double step = c * std::sqrt(double(dx * dx + dy * dy));
          auto x = static_cast<std::ptrdiff_t>(col), y = static_cast<std::ptrdiff_t>(row);
          for (double d = step; d <= reach + 1e-9; d += step) {
            x += dx, y += dy;
            if (x < 0 || y < 0 || x >= static_cast<std::ptrdiff_t>(cols) || y >= static_cast<std::ptrdiff_t>(rows)) break;
            const std::size_t b = static_cast<std::size_t>(y) * cols + static_cast<std::size_t>(x);
            if (std::isnan(g.z[b])) continue;
            visit(a, b, d);
            break;
          }
        }
      }
  };
  for_each_pair([&](std::size_t a, std::size_t b, double d) {
    if (gentle(g.z[a], g.z[b], d)) parent[root(a)] = static_cast<std::uint32_t>(root(b));
  });
  std::vector<std::uint32_t> area(cells, 0);
  for (std::size_t k = 0; k < cells; ++k)
    if (!std::isnan(g.z[k])) ++area[root(k)];
  const auto min_base = static_cast<std::uint32_t>(std::ceil(kMinBaseArea / (c * c)));
  // Each patch's bounding box in cells: a patch inside another's box (a pit, a sunken
  // yard, an excavation) is enclosed by it, and its walls do not raise the one around it.
  struct CellBox {
    std::size_t col0 = SIZE_MAX, row0 = SIZE_MAX, col1 = 0, row1 = 0;
    bool inside(const CellBox& o) const { return col0 >= o.col0 && col1 <= o.col1 && row0 >= o.row0 && row1 <= o.row1; }
  };
  std::vector<CellBox> box(cells);
  for (std::size_t k = 0; k < cells; ++k) {
    if (std::isnan(g.z[k])) continue;
    CellBox& b = box[root(k)];
    const std::size_t col = k % cols, row = k / cols;
    b.col0 = std::min(b.col0, col), b.col1 = std::max(b.col1, col);
    b.row0 = std::min(b.row0, row), b.row1 = std::max(b.row1, row);
  }
  std::vector<std::uint32_t> upper(cells, 0), lower(cells, 0);  // wall pairs, by patch root
  std::vector<double> rise(cells, 0.0);                          // summed over the upper pairs
  for_each_pair([&](std::size_t a, std::size_t b, double) {
    const std::size_t ra = root(a), rb = root(b);
    if (ra == rb) return;
    const bool a_above = g.z[a] > g.z[b];
    const std::size_t high = a_above ? ra : rb, low = a_above ? rb : ra;
    if (area[low] >= min_base && !box[low].inside(box[high])) {
      ++upper[high];
      rise[high] += std::abs(double{g.z[a]} - double{g.z[b]});
    }
    if (area[high] >= min_base) ++lower[low];
  });
  // A roof is flat beside its walls: its heights span less than the walls rise. A
  // hillside cut into patches by voids spans more than its steps.
  std::vector<float> low_z(cells, INFINITY), high_z(cells, -INFINITY);
  for (std::size_t k = 0; k < cells; ++k) {
    if (std::isnan(g.z[k])) continue;
    const std::size_t r = root(k);
    low_z[r] = std::min(low_z[r], g.z[k]);
    high_z[r] = std::max(high_z[r], g.z[k]);
  }
  std::vector<bool> raised(cells, false);
  for (std::size_t k = 0; k < cells; ++k) {
    if (std::isnan(g.z[k])) continue;
    const std::size_t r = root(k);
    raised[k] = upper[r] > lower[r] && double{high_z[r]} - double{low_z[r]} < rise[r] / upper[r];
  }
  return raised;
}

// Pits of the low-outlier opening that are ground seen through a canopy. Under dense
// vegetation most cells' lowest point is a leaf or a branch, and the few cells that reach
// the ground lie metres below all their neighbours: the opening takes each for a pit. Yet
// they continue one another, cell to cell a few metres apart, across the whole forest,
// while echoes below glass or water come in clusters a few metres wide. Pits join when
// they lie within kLowOutlierWindow of each other and within kPitDepth + kPitSlope x
// distance in height (the reach unsupported() allows); a network wider than
// kPitNetworkExtent is ground.
std::vector<bool> pits_in_wide_networks(const ElevationGrid& g, const std::vector<bool>& pit) {
  const std::size_t cols = g.cols, rows = g.rows;
  // Per pit, not per cell: a survey's grid can hold 10^8 cells and only a few pits.
  std::vector<std::size_t> pits;  // cell indices, ascending
  for (std::size_t k = 0; k < g.cells(); ++k)
    if (pit[k]) pits.push_back(k);
  const auto index_of = [&](std::size_t cell) {
    return static_cast<std::size_t>(std::lower_bound(pits.begin(), pits.end(), cell) - pits.begin());
  };
  std::vector<std::size_t> parent(pits.size());
  for (std::size_t p = 0; p < pits.size(); ++p) parent[p] = p;
  const auto root = [&](std::size_t p) {
    while (parent[p] != p) p = parent[p] = parent[parent[p]];
    return p;
  };
  const auto r = static_cast<std::ptrdiff_t>(std::floor(kLowOutlierWindow / g.cell));
  for (std::size_t p = 0; p < pits.size(); ++p) {
    const std::size_t k = pits[p];
    const auto i = static_cast<std::ptrdiff_t>(k % cols), j = static_cast<std::ptrdiff_t>(k / cols);
    // Each pair once: the rows after this one, and the cells after it in its own row.
    for (std::ptrdiff_t jj = j; jj <= std::min(static_cast<std::ptrdiff_t>(rows) - 1, j + r); ++jj)
      for (std::ptrdiff_t ii = std::max<std::ptrdiff_t>(0, i - r);
           ii <= std::min(static_cast<std::ptrdiff_t>(cols) - 1, i + r); ++ii) {
        if (jj == j && ii <= i) continue;
        const auto q = static_cast<std::size_t>(jj) * cols + static_cast<std::size_t>(ii);
        if (!pit[q]) continue;
        const double d = std::hypot(static_cast<double>(ii - i), static_cast<double>(jj - j)) * g.cell;
        if (d <= kLowOutlierWindow && std::abs(double{g.z[k]} - double{g.z[q]}) <= kPitDepth + kPitSlope * d)
          parent[root(p)] = root(index_of(q));
      }
  }
  struct Span {
    std::size_t col0 = SIZE_MAX, row0 = SIZE_MAX, col1 = 0, row1 = 0;
  };
  std::vector<Span> span(pits.size());
  for (std::size_t p = 0; p < pits.size(); ++p) {
    Span& s = span[root(p)];
    const std::size_t col = pits[p] % cols, row = pits[p] / cols;
    s.col0 = std::min(s.col0, col), s.col1 = std::max(s.col1, col);
    s.row0 = std::min(s.row0, row), s.row1 = std::max(s.row1, row);
  }
  std::vector<bool> wide(g.cells(), false);
  for (std::size_t p = 0; p < pits.size(); ++p) {
    const Span& s = span[root(p)];
    wide[pits[p]] = static_cast<double>(std::max(s.col1 - s.col0, s.row1 - s.row0)) * g.cell > kPitNetworkExtent;
  }
  return wide;
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
  // A stray point kilometres from the survey stretches the grid over empty ground: say so
  // before allocating it, with the extent that makes it large.
  const double cells = cols_d * rows_d, budget = grid_memory_budget();
  if (cells > kMaxCells || cells * kBytesPerCell > budget) {
    const double bytes = cells * kBytesPerCell;
    const std::string need = std::isfinite(bytes) ? "about " + gigabytes(bytes) : "more memory than any machine holds";
    char what[512];
    std::snprintf(what, sizeof what,
                  "smrf: the points span %.10g x %.10g m, from (%.10g, %.10g) to (%.10g, %.10g) in metres: a grid of "
                  "%.10g x %.10g cells of %g m would need %s, more than SMRF may take here (%s)",
                  maxx - minx, maxy - miny, minx, miny, maxx, maxy, cols_d, rows_d, c, need.c_str(),
                  gigabytes(std::min(budget, kMaxCells * kBytesPerCell)).c_str());
    throw InvalidArgument(std::string(what) +
                          "; remove points far from the survey (--filter outlier, or --where on X and Y), crop it, "
                          "or give a larger cell");
  }
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
  // found as peaks of its negation, but for those that are ground under a canopy.
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
  const std::vector<bool> under_canopy = pits_in_wide_networks(zmin, pit);
  for (std::size_t k = 0; k < zmin.cells(); ++k)
    if (pit[k] && !under_canopy[k]) zmin.z[k] = NAN;

  ElevationGrid filled = zmin;
  detail::inpaint(filled);
  const int max_radius = std::max(1, static_cast<int>(std::ceil(options.window / c)));
  const std::vector<bool> object = progressive_objects(filled, max_radius, options.slope);

  ElevationGrid surface = zmin;
  for (std::size_t k = 0; k < surface.cells(); ++k)
    if (object[k]) surface.z[k] = NAN;
  const std::vector<bool> raised = raised_plateaus(surface);
  for (std::size_t k = 0; k < surface.cells(); ++k)
    if (raised[k]) surface.z[k] = NAN;
  detail::inpaint(surface);
  const auto slope_reach = static_cast<std::size_t>(std::max(1L, std::lround(kSlopeBaseline / c)));
  const std::vector<float> slope = slope_of(surface, slope_reach);

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
    // Noise stays noise. Overlap points (class 12 of LAS 1.1-1.3: the survey marked them
    // to be left out of its products) helped to find the surface but keep their mark.
    if (values[i] == 7 || values[i] == 18 || values[i] == 12) continue;
    values[i] = ground[i] ? 2.0 : 1.0;
    found += ground[i];
  }
  return found;
}

}  // namespace vola::filters
