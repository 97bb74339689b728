#include "vola/raycast/path_planner.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
#include <queue>
#include <string>
#include <unordered_map>
#include <unordered_set>

#include "vola/error.hpp"

namespace vola::raycast {
namespace {

using Cell = std::array<std::int64_t, 3>;

std::string show(const Point& p) {
  char text[96];
  std::snprintf(text, sizeof text, "(%.6g, %.6g, %.6g)", p[0], p[1], p[2]);
  return text;
}

double distance(const Point& a, const Point& b) {
  return std::sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]));
}

// Is every voxel of `known` whose cell comes within `radius` of `p` (grid units) there?
// Cells off the grid are unknown. (2r + 2)^3 lookups at most: for a robot a few voxels wide.
bool known_around(const Tree& known, const Point& p, double radius) {
  std::array<std::int64_t, 3> lo{}, hi{};
  for (int a = 0; a < 3; ++a) {
    lo[a] = static_cast<std::int64_t>(std::floor(p[a] - radius));
    hi[a] = static_cast<std::int64_t>(std::floor(p[a] + radius));
    if (lo[a] < 0 || hi[a] >= static_cast<std::int64_t>(known.side())) return false;
  }
  const auto gap = [](double x, std::int64_t cell) {  // distance from x to [cell, cell + 1] on one axis
    const double c = static_cast<double>(cell);
    return x < c ? c - x : x > c + 1.0 ? x - (c + 1.0) : 0.0;
  };
  for (std::int64_t z = lo[2]; z <= hi[2]; ++z)
    for (std::int64_t y = lo[1]; y <= hi[1]; ++y)
      for (std::int64_t x = lo[0]; x <= hi[0]; ++x) {
        const double dx = gap(p[0], x), dy = gap(p[1], y), dz = gap(p[2], z);
        if (dx * dx + dy * dy + dz * dz > radius * radius) continue;
        if (!known.contains(static_cast<std::uint32_t>(x), static_cast<std::uint32_t>(y), static_cast<std::uint32_t>(z)))
          return false;
      }
  return true;
}

// One planning grid: a tree (maybe a level of detail) and the inflation radius in its
// cells; with `known`, unknown space counts as an obstacle too.
class Grid {
 public:
  Grid(const Tree& tree, double radius, const Tree* known)
      : collider_(tree), radius_(radius), side_(tree.side()), known_(known) {}
  bool inside(const Cell& c) const {
    return c[0] >= 0 && c[1] >= 0 && c[2] >= 0 && c[0] < side_ && c[1] < side_ && c[2] < side_;
  }
  bool free(const Cell& c) {
    const Key key = encode(static_cast<std::uint32_t>(c[0]), static_cast<std::uint32_t>(c[1]),
                           static_cast<std::uint32_t>(c[2]));
    const auto found = free_.find(key);
    if (found != free_.end()) return found->second;
    const bool f = !collider_.sphere(centre(c), radius_) && (!known_ || known_around(*known_, centre(c), radius_));
    free_.emplace(key, f);
    return f;
  }
  static Point centre(const Cell& c) {
    return {static_cast<double>(c[0]) + 0.5, static_cast<double>(c[1]) + 0.5, static_cast<double>(c[2]) + 0.5};
  }
  // Does a sphere of the radius swept from a to b stay clear? Spheres of radius
  // r + h/2 at steps of h cover the swept volume.
  bool clear(const Point& a, const Point& b) const {
    constexpr double h = 0.25;
    const double length = distance(a, b);
    const auto steps = static_cast<std::int64_t>(std::ceil(length / h));
    for (std::int64_t i = 0; i <= steps; ++i) {
      const double f = steps ? static_cast<double>(i) / static_cast<double>(steps) : 0.0;
      const Point p{a[0] + f * (b[0] - a[0]), a[1] + f * (b[1] - a[1]), a[2] + f * (b[2] - a[2])};
      if (collider_.sphere(p, radius_ + h / 2)) return false;
      if (known_ && !known_around(*known_, p, radius_ + h / 2)) return false;
    }
    return true;
  }
  std::int64_t side() const { return side_; }

 private:
  Collider collider_;
  double radius_;
  std::int64_t side_;
  const Tree* known_;
  std::unordered_map<Key, bool> free_;
};

Key key_of(const Cell& c) {
  return encode(static_cast<std::uint32_t>(c[0]), static_cast<std::uint32_t>(c[1]), static_cast<std::uint32_t>(c[2]));
}

// A* from start to goal over free cells; `allowed` (when given) limits the cells searched.
std::optional<std::vector<Cell>> astar(Grid& grid, const Cell& start, const Cell& goal,
                                       const std::unordered_set<Key>* allowed, std::uint64_t max_expansions,
                                       double& cost, std::uint64_t& expanded) {
  struct Open {
    double f, g;
    Cell cell;
    bool operator>(const Open& o) const { return f > o.f; }
  };
  std::priority_queue<Open, std::vector<Open>, std::greater<>> open;
  std::unordered_map<Key, std::pair<double, Key>> best;  // g and parent
  const Point goal_centre = Grid::centre(goal);
  best[key_of(start)] = {0.0, key_of(start)};
  open.push({distance(Grid::centre(start), goal_centre), 0.0, start});
  while (!open.empty()) {
    const Open top = open.top();
    open.pop();
    const Key key = key_of(top.cell);
    if (top.g > best[key].first) continue;  // a stale entry
    if (++expanded > max_expansions) return std::nullopt;
    if (top.cell == goal) {
      cost = top.g;
      std::vector<Cell> path;
      for (Key k = key;; k = best[k].second) {
        const Voxel v = decode(k);
        path.push_back({v.x, v.y, v.z});
        if (k == key_of(start)) break;
      }
      std::reverse(path.begin(), path.end());
      return path;
    }
    for (int dz = -1; dz <= 1; ++dz)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          if (!dx && !dy && !dz) continue;
          const Cell n{top.cell[0] + dx, top.cell[1] + dy, top.cell[2] + dz};
          if (!grid.inside(n)) continue;
          const Key nk = key_of(n);
          if (allowed && !allowed->count(nk)) continue;
          const double g = top.g + std::sqrt(static_cast<double>(dx * dx + dy * dy + dz * dz));
          const auto found = best.find(nk);
          if (found != best.end() && found->second.first <= g) continue;
          if (!grid.free(n)) continue;
          best[nk] = {g, key};
          open.push({g + distance(Grid::centre(n), goal_centre), g, n});
        }
  }
  return std::nullopt;
}

Cell cell_of(const Point& p, double cell_size) {
  return {static_cast<std::int64_t>(std::floor(p[0] / cell_size)), static_cast<std::int64_t>(std::floor(p[1] / cell_size)),
          static_cast<std::int64_t>(std::floor(p[2] / cell_size))};
}

}  // namespace

PlannedPath plan_path(const Tree& tree, const Point& start, const Point& goal, const PlanOptions& options) {
  for (int a = 0; a < 3; ++a)
    if (!std::isfinite(start[a]) || !std::isfinite(goal[a])) throw InvalidArgument("plan: start and goal must be finite");
  if (!(options.radius >= 0.0) || !std::isfinite(options.radius)) throw InvalidArgument("plan: the radius must be >= 0");
  const int level = options.level < 0 ? tree.depth() - 1 : options.level;
  if (level >= tree.depth())
    throw InvalidArgument("plan: level " + std::to_string(level) + " is finer than the tree (levels 0.." +
                          std::to_string(tree.depth() - 1) + ")");
  if (options.known && options.known->depth() != tree.depth())
    throw InvalidArgument("plan: the known voxels' tree has depth " + std::to_string(options.known->depth()) +
                          ", the obstacles' " + std::to_string(tree.depth()) + ": they must share one grid");
  const Tree planning = level == tree.depth() - 1 ? tree : tree.level_of_detail(level + 1);
  std::optional<Tree> known_planning;
  if (options.known) known_planning = level == tree.depth() - 1 ? *options.known : options.known->level_of_detail(level + 1);
  const double cell_size = std::ldexp(1.0, 2 * (tree.depth() - 1 - level));
  Grid grid(planning, options.radius / cell_size, known_planning ? &*known_planning : nullptr);
  const Cell from = cell_of(start, cell_size), to = cell_of(goal, cell_size);
  const auto side = static_cast<double>(tree.side());
  for (const auto& [name, p, c] : {std::tuple{"start", start, from}, std::tuple{"goal", goal, to}}) {
    if (!grid.inside(c))
      throw InvalidArgument(std::string("plan: the ") + name + " " + show(p) + " is outside the volume [0, " +
                            std::to_string(static_cast<long long>(side)) + ")^3 (grid coordinates)");
    if (!grid.free(c))
      throw InvalidArgument(std::string("plan: the ") + name + " " + show(p) + " is inside an obstacle" +
                            (options.known ? " or unknown space" : "") +
                            (options.radius > 0 ? " or closer than the radius to one" : ""));
  }

  PlannedPath out;
  std::optional<std::vector<Cell>> cells;
  if (options.hierarchical && level >= 2) {
    // Coarse plan two levels up, then the fine search inside the coarse cells of that
    // path and their neighbours.
    PlanOptions coarse = options;
    coarse.level = level - 2;
    coarse.hierarchical = false;
    coarse.smooth = false;
    std::optional<PlannedPath> rough;
    try {
      rough = plan_path(tree, start, goal, coarse);
    } catch (const InvalidArgument&) {
      // Coarse cells are occupied when any voxel is: the fine search may still succeed.
    }
    if (rough) {
      out.expanded += rough->expanded;
      std::unordered_set<Key> corridor;
      for (const Point& p : rough->points) {
        const Cell c = cell_of(p, cell_size * 16.0);  // the coarse cell
        for (int dz = -1; dz <= 1; ++dz)
          for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx)
              for (std::int64_t z = 0; z < 16; ++z)
                for (std::int64_t y = 0; y < 16; ++y)
                  for (std::int64_t x = 0; x < 16; ++x) {
                    const Cell f{(c[0] + dx) * 16 + x, (c[1] + dy) * 16 + y, (c[2] + dz) * 16 + z};
                    if (grid.inside(f)) corridor.insert(key_of(f));
                  }
      }
      cells = astar(grid, from, to, &corridor, options.max_expansions, out.cost, out.expanded);
    }
  }
  if (!cells) cells = astar(grid, from, to, nullptr, options.max_expansions, out.cost, out.expanded);
  if (!cells)
    throw InvalidArgument("plan: the goal " + show(goal) + " cannot be reached from " + show(start) + " (" +
                          std::to_string(out.expanded) + " cells searched)");

  std::vector<Point> centres;
  for (const Cell& c : *cells) centres.push_back(Grid::centre(c));
  std::vector<Point> kept{centres.front()};
  if (options.smooth) {
    // Greedy line of sight: from each kept point, the furthest later point in clear view.
    for (std::size_t i = 0; i + 1 < centres.size();) {
      std::size_t j = centres.size() - 1;
      while (j > i + 1 && !grid.clear(centres[i], centres[j])) --j;
      kept.push_back(centres[j]);
      i = j;
    }
  } else {
    kept = centres;
  }
  for (Point& p : kept)
    for (double& x : p) x *= cell_size;
  out.points = kept;
  for (std::size_t i = 1; i < kept.size(); ++i) out.length += distance(kept[i - 1], kept[i]);
  out.cost *= cell_size;
  return out;
}

}  // namespace vola::raycast
