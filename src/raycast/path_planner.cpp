#include "vola/raycast/path_planner.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <limits>
#include <memory>
#include <optional>
#include <queue>
#include <string>
#include <tuple>
#include <unordered_map>
#include <unordered_set>
#include <vector>

#include "vola/error.hpp"
#include "vola/raycast/clearance_field.hpp"
#include "vola/raycast/world.hpp"

namespace vola::raycast {
namespace {

using Cell = std::array<std::int64_t, 3>;
constexpr std::int64_t kBrick = ClearanceField::kBrick;

std::string show_xyz(const Point& p) {
  char text[128];
  std::snprintf(text, sizeof text, "(%.10g, %.10g, %.10g)", p[0], p[1], p[2]);
  return text;
}

// A point as the caller gave it: in world coordinates when the options carry the frame.
std::string show(const Point& grid, const PlanOptions& options) {
  return show_xyz(options.world ? grid_to_world(*options.world, grid) : grid);
}

// The volume's extent, in the coordinates the caller uses.
std::string show_volume(double side, const PlanOptions& options) {
  if (!options.world) return "[0, " + std::to_string(static_cast<long long>(side)) + ")^3 (grid coordinates)";
  return show_xyz(grid_to_world(*options.world, {0, 0, 0})) + " to " +
         show_xyz(grid_to_world(*options.world, {side, side, side})) + " (world coordinates)";
}

double distance(const Point& a, const Point& b) {
  return std::sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]));
}

Point centre(const Cell& c) {
  return {static_cast<double>(c[0]) + 0.5, static_cast<double>(c[1]) + 0.5, static_cast<double>(c[2]) + 0.5};
}

// The cost of the cheapest 26-neighbour walk through empty space: the heuristic, exact
// without obstacles and consistent with the move costs, so A* stays optimal and, unlike
// the Euclidean distance, does not expand the whole lens of equally good staircases.
double octile(const Cell& a, const Cell& b) {
  std::array<double, 3> d{std::fabs(static_cast<double>(a[0] - b[0])), std::fabs(static_cast<double>(a[1] - b[1])),
                          std::fabs(static_cast<double>(a[2] - b[2]))};
  std::sort(d.begin(), d.end());  // d[0] <= d[1] <= d[2]
  return std::sqrt(3.0) * d[0] + std::sqrt(2.0) * (d[1] - d[0]) + (d[2] - d[1]);
}

// The 26 moves, and for each the cells (as bits of the 3x3x3 neighbourhood, bit
// (dx+1) + 3(dy+1) + 9(dz+1)) that must be free for it: every cell of the box the move
// spans. Why: the distance from a point of that box to a voxel's cube is smallest, per
// axis, at one of the box's two faces, i.e. at one of its corner cells' centres; so when
// all of them are free the whole move keeps the sphere clear. Without this a diagonal
// move between two free cells can cut a corner closer than the radius.
struct Moves {
  std::array<Cell, 26> step{};
  std::array<double, 26> cost{};
  std::array<std::uint32_t, 26> needs{};
  Moves() {
    int k = 0;
    for (int dz = -1; dz <= 1; ++dz)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          if (!dx && !dy && !dz) continue;
          step[k] = {dx, dy, dz};
          cost[k] = std::sqrt(static_cast<double>(dx * dx + dy * dy + dz * dz));
          for (int z = std::min(0, dz); z <= std::max(0, dz); ++z)
            for (int y = std::min(0, dy); y <= std::max(0, dy); ++y)
              for (int x = std::min(0, dx); x <= std::max(0, dx); ++x)
                needs[k] |= std::uint32_t{1} << ((x + 1) + 3 * (y + 1) + 9 * (z + 1));
          ++k;
        }
  }
};
const Moves kMoves;

std::uint64_t brick_key(std::int64_t bx, std::int64_t by, std::int64_t bz) {
  return static_cast<std::uint64_t>(bx) | static_cast<std::uint64_t>(by) << 21 | static_cast<std::uint64_t>(bz) << 42;
}

Cell unpack(std::uint64_t key) {
  return {static_cast<std::int64_t>(key & 0x1fffff), static_cast<std::int64_t>((key >> 21) & 0x1fffff),
          static_cast<std::int64_t>(key >> 42)};
}

// An open-list entry, the cell packed as brick_key packs a brick: 24 bytes, so that the
// heap's sifting (most of a large search's time) touches fewer cache lines.
struct Open {
  double f, g;
  std::uint64_t cell;
  bool operator>(const Open& o) const { return f > o.f || (f == o.f && g < o.g); }  // ties: deeper first
};

// The coarse cells of the hierarchical search, kCoarse^3 cells (a VOLA leaf block): kSub^3
// of them per brick. Measured on the cities of tests/raycast/test_plan_city.cpp: coarse
// cells of 8 gave a cost 2.8% above the optimum on one (their routes miss passages a few
// cells wide), 4 stays within 1% on all three.
constexpr std::int64_t kCoarse = 4;
constexpr std::int64_t kSub = kBrick / kCoarse;
constexpr std::uint16_t kCoarseRow = static_cast<std::uint16_t>((1u << kCoarse) - 1u);

// The search's own state, by brick like the field, allocated when the search first
// reaches a brick: the cells it may enter (free, and inside the corridor), g, and the move
// that reached each cell.
struct BrickState {
  std::array<std::uint16_t, 256> open;  // row y + 16 z, bit x
  std::array<double, 4096> g;
  std::array<std::uint8_t, 4096> via;  // move index + 1 (27: the start); 0: not reached; bit 7: closed
};

class Search {
 public:
  // `allowed`: the coarse cells (keys of cell / kCoarse) the search may enter; null: all.
  Search(ClearanceField& field, const std::unordered_set<std::uint64_t>* allowed) : field_(field), allowed_(allowed) {}

  // A* from start to goal over the open cells.
  std::optional<std::vector<Cell>> run(const Cell& start, const Cell& goal, std::uint64_t max_expansions, double& cost,
                                       std::uint64_t& expanded) {
    std::priority_queue<Open, std::vector<Open>, std::greater<>> open;
    if (!state_of(start)) return std::nullopt;  // the start's coarse cell is outside the corridor
    auto [g0, v0] = state(start);
    *g0 = 0.0;
    *v0 = 27;
    open.push({octile(start, goal), 0.0, brick_key(start[0], start[1], start[2])});
    while (!open.empty()) {
      const Open top = open.top();
      open.pop();
      const Cell cell = unpack(top.cell);
      auto [g, via] = state(cell);
      if (*via & 0x80) continue;  // closed: a stale entry
      *via |= 0x80;
      if (++expanded > max_expansions) return std::nullopt;
      if (cell == goal) {
        cost = top.g;
        return trace(start, goal);
      }
      const std::uint32_t free = neighbourhood(cell);
      for (int k = 0; k < 26; ++k) {
        if ((free & kMoves.needs[k]) != kMoves.needs[k]) continue;
        const Cell n{cell[0] + kMoves.step[k][0], cell[1] + kMoves.step[k][1], cell[2] + kMoves.step[k][2]};
        const double ng = top.g + kMoves.cost[k];
        auto [gn, vn] = state(n);
        if (*vn & 0x80 || ng >= *gn) continue;
        *gn = ng;
        *vn = static_cast<std::uint8_t>(k + 1);
        open.push({ng + octile(n, goal), ng, brick_key(n[0], n[1], n[2])});
      }
    }
    return std::nullopt;
  }

 private:
  // The brick's state; null when the search may enter none of its cells.
  BrickState* brick(std::int64_t bx, std::int64_t by, std::int64_t bz) {
    const std::uint64_t key = brick_key(bx, by, bz);
    if (key == last_key_) return last_;
    auto [it, added] = states_.try_emplace(key);
    if (added) {
      // Which coarse cells the corridor lets in, as masks of the rows (per y and z sub-cell).
      std::array<std::uint16_t, kSub * kSub> sub_rows{};
      bool any = !allowed_;
      for (std::int64_t sz = 0; sz < kSub; ++sz)
        for (std::int64_t sy = 0; sy < kSub; ++sy)
          for (std::int64_t sx = 0; sx < kSub; ++sx)
            if (!allowed_ || allowed_->count(brick_key(bx * kSub + sx, by * kSub + sy, bz * kSub + sz))) {
              sub_rows[static_cast<std::size_t>(sy + kSub * sz)] |= static_cast<std::uint16_t>(kCoarseRow << (sx * kCoarse));
              any = true;
            }
      if (any) {
        it->second = std::make_unique<BrickState>();
        BrickState& b = *it->second;
        const std::uint16_t* rows = field_.brick(bx, by, bz);
        for (int r = 0; r < 256; ++r)
          b.open[r] = static_cast<std::uint16_t>(rows[r] & sub_rows[static_cast<std::size_t>((r & 15) / kCoarse + kSub * ((r >> 4) / kCoarse))]);
        b.g.fill(std::numeric_limits<double>::infinity());
        b.via.fill(0);
      }
    }
    last_key_ = key;
    last_ = it->second.get();
    return last_;
  }
  BrickState* state_of(const Cell& c) { return brick(c[0] / kBrick, c[1] / kBrick, c[2] / kBrick); }
  std::pair<double*, std::uint8_t*> state(const Cell& c) {
    BrickState* b = state_of(c);
    const auto i = static_cast<std::size_t>((c[0] % kBrick) + kBrick * ((c[1] % kBrick) + kBrick * (c[2] % kBrick)));
    return {&b->g[i], &b->via[i]};
  }

  // The open cells of the 3x3x3 neighbourhood as bits (dx+1) + 3(dy+1) + 9(dz+1).
  std::uint32_t neighbourhood(const Cell& c) {
    std::uint32_t bits = 0;
    const std::int64_t side = field_.side(), lx = c[0] % kBrick;
    for (int dz = -1; dz <= 1; ++dz)
      for (int dy = -1; dy <= 1; ++dy) {
        const std::int64_t y = c[1] + dy, z = c[2] + dz;
        if (y < 0 || z < 0 || y >= side || z >= side) continue;
        const auto row_index = static_cast<std::size_t>((y % kBrick) + kBrick * (z % kBrick));
        const unsigned shift = static_cast<unsigned>(3 * (dy + 1) + 9 * (dz + 1));
        if (lx >= 1 && lx < kBrick - 1) {  // the three cells in one brick: one row
          const BrickState* b = brick(c[0] / kBrick, y / kBrick, z / kBrick);
          if (b) bits |= ((static_cast<std::uint32_t>(b->open[row_index]) >> (lx - 1)) & 7u) << shift;
          continue;
        }
        for (int dx = -1; dx <= 1; ++dx) {
          const std::int64_t x = c[0] + dx;
          if (x < 0 || x >= side) continue;
          const BrickState* b = brick(x / kBrick, y / kBrick, z / kBrick);
          if (b && (b->open[row_index] >> (x % kBrick)) & 1u) bits |= std::uint32_t{1} << (shift + static_cast<unsigned>(dx + 1));
        }
      }
    return bits;
  }

  std::vector<Cell> trace(const Cell& start, const Cell& goal) {
    std::vector<Cell> path{goal};
    for (Cell c = goal; c != start;) {
      const int k = (*state(c).second & 0x7f) - 1;
      for (int a = 0; a < 3; ++a) c[a] -= kMoves.step[k][a];
      path.push_back(c);
    }
    std::reverse(path.begin(), path.end());
    return path;
  }

  ClearanceField& field_;
  const std::unordered_set<std::uint64_t>* allowed_;
  std::unordered_map<std::uint64_t, std::unique_ptr<BrickState>> states_;
  std::uint64_t last_key_ = ~std::uint64_t{0};
  BrickState* last_ = nullptr;
};

// Are at least `needed` cells of the coarse cell free?
bool coarse_free(ClearanceField& field, const Cell& c, int needed) {
  const std::uint16_t* rows = field.brick(c[0] / kSub, c[1] / kSub, c[2] / kSub);
  const auto mask = static_cast<std::uint16_t>(kCoarseRow << ((c[0] % kSub) * kCoarse));
  int free = 0;
  for (std::int64_t z = (c[2] % kSub) * kCoarse; z < (c[2] % kSub + 1) * kCoarse; ++z)
    for (std::int64_t y = (c[1] % kSub) * kCoarse; y < (c[1] % kSub + 1) * kCoarse; ++y)
      free += std::popcount(static_cast<unsigned>(rows[y + kBrick * z] & mask));
  return free >= needed;
}

// A* over coarse cells (kCoarse^3 cells) with at least `needed` free cells, the start's
// and goal's allowed whatever they hold: a guide for the fine search, cheap because a
// brick far from every obstacle is free without a computation. Why not "any free cell":
// a coarse cell with free cells on both sides of a wall would let the route through the
// wall; with at least half free, two neighbouring coarse cells are both passable across
// a wall only when the wall's blocked band is thinner than a coarse cell. Wholly free
// (needed = all) never crosses a wall but misses passages narrower than two cells.
std::optional<std::vector<Cell>> coarse_route(ClearanceField& field, const Cell& start, const Cell& goal, int needed,
                                              std::uint64_t max_expansions, std::uint64_t& expanded) {
  constexpr std::uint64_t kEmpty = ~std::uint64_t{0};
  // The heuristic weighted by 2%: the route is then at most 2% above the coarse optimum,
  // and the search floods far fewer cells behind buildings (a 200 m city with a solid
  // ground: 3.1 s of CPU down to 2.0 s). Measured on the test cities: the same plans as
  // unweighted; with 1.05 one came out 0.96% above the optimum (0.73% unweighted), with
  // 1.2 2.2%.
  constexpr double kCoarseWeight = 1.02;
  const std::int64_t side = field.bricks_per_side() * kSub;
  // One entry per coarse cell looked at: whether it is passable (decided once), and for
  // those reached, g, the parent and whether it is closed. An open-addressing table: the
  // search looks up 27 cells per expansion, and std::unordered_map's scattered nodes made
  // those lookups two thirds of a city plan.
  struct Node {
    std::uint64_t key = kEmpty;
    double g = std::numeric_limits<double>::infinity();
    std::uint64_t parent = 0;
    bool passable = false, closed = false;
  };
  std::vector<Node> table(std::size_t{1} << 16);
  std::size_t used = 0;
  const auto slot = [&](std::uint64_t k) {
    std::size_t i = static_cast<std::size_t>((k * 0x9E3779B97F4A7C15ull) >> 20) & (table.size() - 1);
    while (table[i].key != k && table[i].key != kEmpty) i = (i + 1) & (table.size() - 1);
    return i;
  };
  const auto key = [](const Cell& c) { return brick_key(c[0], c[1], c[2]); };
  std::priority_queue<Open, std::vector<Open>, std::greater<>> open;
  // Room for `more` new entries at a load of at most one half: entries move only here.
  const auto reserve = [&](std::size_t more) {
    if (2 * (used + more) <= table.size()) return;
    std::vector<Node> old(table.size() * 2);
    old.swap(table);
    for (const Node& n : old)
      if (n.key != kEmpty) table[slot(n.key)] = n;
  };
  const auto node = [&](const Cell& c) -> Node& {
    const std::uint64_t k = key(c);
    const std::size_t i = slot(k);
    if (table[i].key == kEmpty) {
      table[i].key = k;
      table[i].passable = c == start || c == goal || coarse_free(field, c, needed);
      ++used;
    }
    return table[i];
  };
  reserve(1);
  node(start).g = 0.0;
  open.push({octile(start, goal), 0.0, key(start)});
  std::array<Node*, 27> around{};
  while (!open.empty()) {
    const Open top = open.top();
    open.pop();
    const Cell cell = unpack(top.cell);
    reserve(27);  // the expansion's lookups below move no entry
    Node& here = node(cell);
    if (here.closed) continue;
    here.closed = true;
    if (++expanded > max_expansions) return std::nullopt;
    if (cell == goal) {
      std::vector<Cell> path;
      for (std::uint64_t at = key(goal);; at = table[slot(at)].parent) {
        path.push_back(unpack(at));
        if (at == key(start)) break;
      }
      std::reverse(path.begin(), path.end());
      return path;
    }
    std::uint32_t free = 0;
    for (int dz = -1; dz <= 1; ++dz)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const int bit = (dx + 1) + 3 * (dy + 1) + 9 * (dz + 1);
          around[static_cast<std::size_t>(bit)] = nullptr;
          const Cell n{cell[0] + dx, cell[1] + dy, cell[2] + dz};
          if (n[0] < 0 || n[1] < 0 || n[2] < 0 || n[0] >= side || n[1] >= side || n[2] >= side) continue;
          Node& other = node(n);
          around[static_cast<std::size_t>(bit)] = &other;
          if (other.passable) free |= std::uint32_t{1} << bit;
        }
    const std::uint64_t k = top.cell;
    for (int m = 0; m < 26; ++m) {
      if ((free & kMoves.needs[m]) != kMoves.needs[m]) continue;
      const Cell n{cell[0] + kMoves.step[m][0], cell[1] + kMoves.step[m][1], cell[2] + kMoves.step[m][2]};
      Node& next = *around[static_cast<std::size_t>((kMoves.step[m][0] + 1) + 3 * (kMoves.step[m][1] + 1) +
                                                    9 * (kMoves.step[m][2] + 1))];
      const double g = top.g + kMoves.cost[m];
      if (next.closed || next.g <= g) continue;
      next.g = g;
      next.parent = k;
      open.push({g + kCoarseWeight * octile(n, goal), g, key(n)});
    }
  }
  return std::nullopt;
}

// Does a sphere of the field's radius swept along the straight segment between two cell
// centres stay clear? Exact for the field's rule, by the argument of Moves: the segment
// is walked through the boxes whose corners are cell centres (a voxel walk on the grid
// shifted by half a cell), and each box it enters needs its corner cells free.
bool clear(ClearanceField& field, const Cell& a, const Cell& b) {
  // In the shifted grid the centres are the integer points: a and b themselves.
  std::array<std::int64_t, 3> box{}, step{};
  std::array<double, 3> t_max{}, t_delta{};
  std::array<int, 3> corners{};  // 1: the box's two corner planes on this axis; 0: only the first
  for (int i = 0; i < 3; ++i) {
    const auto d = static_cast<double>(b[i] - a[i]);
    corners[i] = d != 0.0;
    step[i] = d > 0 ? 1 : -1;
    box[i] = d >= 0 ? a[i] : a[i] - 1;  // the box a lies in, on the side the segment leaves by
    t_delta[i] = d != 0.0 ? 1.0 / std::fabs(d) : std::numeric_limits<double>::infinity();
    t_max[i] = t_delta[i];
  }
  for (;;) {
    for (int z = 0; z <= corners[2]; ++z)
      for (int y = 0; y <= corners[1]; ++y)
        for (int x = 0; x <= corners[0]; ++x)
          if (!field.free(box[0] + x, box[1] + y, box[2] + z)) return false;
    int axis = 0;
    if (t_max[1] < t_max[axis]) axis = 1;
    if (t_max[2] < t_max[axis]) axis = 2;
    if (t_max[axis] >= 1.0 - 1e-12) return true;
    box[axis] += step[axis];
    t_max[axis] += t_delta[axis];
  }
}

Cell cell_of(const Point& p, double cell_size) {
  return {static_cast<std::int64_t>(std::floor(p[0] / cell_size)), static_cast<std::int64_t>(std::floor(p[1] / cell_size)),
          static_cast<std::int64_t>(std::floor(p[2] / cell_size))};
}

// The coarse cells of `route` and every coarse cell within `grow` of one.
std::unordered_set<std::uint64_t> corridor(const std::vector<Cell>& route, int grow, std::int64_t side) {
  std::unordered_set<std::uint64_t> bricks;
  for (const Cell& c : route)
    for (int dz = -grow; dz <= grow; ++dz)
      for (int dy = -grow; dy <= grow; ++dy)
        for (int dx = -grow; dx <= grow; ++dx) {
          const Cell n{c[0] + dx, c[1] + dy, c[2] + dz};
          if (n[0] >= 0 && n[1] >= 0 && n[2] >= 0 && n[0] < side && n[1] < side && n[2] < side)
            bricks.insert(brick_key(n[0], n[1], n[2]));
        }
  return bricks;
}

// The free cells reachable from `seed` by face moves, when they are fewer than `budget`
// and do not include `other`: a closed region, which no search can leave (a diagonal
// move cuts no corner, so the cells it passes by are free and face moves join its ends
// too). Its size then; none otherwise. A goal sealed in a cavity took the full search
// 20 M cells (80 s) to give up on.
std::optional<std::uint64_t> closed_region(ClearanceField& field, const Cell& seed, const Cell& other,
                                           std::uint64_t budget) {
  const auto key = [](const Cell& c) {
    return (static_cast<std::uint64_t>(c[0]) << 42) | (static_cast<std::uint64_t>(c[1]) << 21) |
           static_cast<std::uint64_t>(c[2]);
  };
  std::unordered_set<std::uint64_t> seen{key(seed)};
  std::vector<Cell> frontier{seed};
  while (!frontier.empty()) {
    const Cell c = frontier.back();
    frontier.pop_back();
    for (int a = 0; a < 3; ++a)
      for (const int step : {-1, 1}) {
        Cell n = c;
        n[a] += step;
        if (!field.inside(n[0], n[1], n[2]) || !field.free(n[0], n[1], n[2]) || !seen.insert(key(n)).second) continue;
        if (n == other || seen.size() > budget) return std::nullopt;
        frontier.push_back(n);
      }
  }
  return seen.size();
}

}  // namespace

PlannedPath plan_path(const Tree& tree, const Point& start, const Point& goal, const PlanOptions& options) {
  for (int a = 0; a < 3; ++a)
    if (!std::isfinite(start[a]) || !std::isfinite(goal[a])) throw InvalidArgument("plan: start and goal must be finite");
  if (!(options.radius >= 0.0) || !std::isfinite(options.radius))
    throw InvalidArgument("plan: the radius must be finite and >= 0");
  const int level = options.level < 0 ? tree.depth() - 1 : options.level;
  if (level >= tree.depth())
    throw InvalidArgument("plan: level " + std::to_string(level) + " is finer than the tree (levels 0.." +
                          std::to_string(tree.depth() - 1) + ")");
  if (options.known && options.known->depth() != tree.depth())
    throw InvalidArgument("plan: the known voxels' tree has depth " + std::to_string(options.known->depth()) +
                          ", the obstacles' " + std::to_string(tree.depth()) + ": they must share one grid");
  // A coarser level: its cells are occupied when any voxel in them is, known when any is.
  // The finest level is the tree itself, not a copy (a copy took its attribute columns
  // too: 54 MB of a city's, which the search never reads).
  const bool finest = level == tree.depth() - 1;
  std::optional<Tree> coarse, known_coarse;
  if (!finest) coarse = tree.level_of_detail(level + 1);
  if (!finest && options.known) known_coarse = options.known->level_of_detail(level + 1);
  const Tree& planning = finest ? tree : *coarse;
  const Tree* known_planning = finest ? options.known : known_coarse ? &*known_coarse : nullptr;
  const double cell_size = std::ldexp(1.0, 2 * (tree.depth() - 1 - level));
  ClearanceField field(planning, options.radius / cell_size, known_planning, options.solid_ground);
  const Cell from = cell_of(start, cell_size), to = cell_of(goal, cell_size);
  const auto side = static_cast<double>(tree.side());
  for (const auto& [name, p, c] : {std::tuple{"start", start, from}, std::tuple{"goal", goal, to}}) {
    if (!field.inside(c[0], c[1], c[2]))
      throw InvalidArgument(std::string("plan: the ") + name + " " + show(p, options) + " is outside the volume " +
                            show_volume(side, options));
    if (!field.free(c[0], c[1], c[2]))
      throw InvalidArgument(std::string("plan: the ") + name + " " + show(p, options) + " is inside an obstacle" +
                            (options.known ? " or unknown space" : "") + (options.solid_ground ? " or the ground" : "") +
                            (options.radius > 0 ? " or closer than the radius to one" : ""));
  }

  // A start or goal sealed in a closed region cannot be left: said instead of "not found
  // within the limit". A small region is found before the search (a few thousand cells:
  // about a millisecond), a larger one once the search gives up.
  const auto refuse_closed = [&](std::uint64_t budget) {
    for (const auto& [name, c, o] : {std::tuple{"goal", to, from}, std::tuple{"start", from, to}})
      if (const auto region = closed_region(field, c, o, budget))
        throw InvalidArgument("plan: the goal " + show(goal, options) + " cannot be reached from " +
                              show(start, options) + ": the " + name + " lies in a closed region of " +
                              std::to_string(*region) + " free cells (a cavity sealed by obstacles" +
                              (options.known ? " or unknown space" : "") +
                              (options.radius > 0 ? ", or by passages narrower than the radius" : "") + ")");
  };
  refuse_closed(std::min<std::uint64_t>(4096, options.max_expansions));

  PlannedPath out;
  std::optional<std::vector<Cell>> cells;
  if (options.hierarchical) {
    // A coarse route through cells at least half free, then the fine search inside the
    // coarse cells around it, wider when the corridor holds no path; then the same along
    // a route through wholly free cells; the full search if none holds a path.
    const Cell coarse_from{from[0] / kCoarse, from[1] / kCoarse, from[2] / kCoarse};
    const Cell coarse_to{to[0] / kCoarse, to[1] / kCoarse, to[2] / kCoarse};
    const std::int64_t coarse_side = field.bricks_per_side() * kSub;
    constexpr int kAll = kCoarse * kCoarse * kCoarse;
    for (const int needed : {kAll / 2, kAll}) {
      const auto route = coarse_route(field, coarse_from, coarse_to, needed, options.max_expansions, out.expanded);
      if (route)
        for (const int grow : {1, 2}) {
          const auto allowed = corridor(*route, grow, coarse_side);
          Search search(field, &allowed);
          cells = search.run(from, to, options.max_expansions, out.cost, out.expanded);
          if (cells) break;
        }
      if (cells) break;
    }
  }
  if (!cells) {
    Search search(field, nullptr);
    cells = search.run(from, to, options.max_expansions, out.cost, out.expanded);
  }
  if (!cells && out.expanded > options.max_expansions) {
    refuse_closed(std::min<std::uint64_t>(std::uint64_t{1} << 24, options.max_expansions));
    throw InvalidArgument("plan: no path from " + show(start, options) + " to " + show(goal, options) +
                          " found within the limit of " + std::to_string(options.max_expansions) +
                          " expanded cells (a larger limit" +
                          (options.hierarchical ? "" : ", or a hierarchical search,") + " may find one)");
  }
  if (!cells)
    throw InvalidArgument("plan: the goal " + show(goal, options) + " cannot be reached from " + show(start, options) + " (" +
                          std::to_string(out.expanded) + " cells searched)");

  std::vector<Cell> kept{cells->front()};
  if (options.smooth) {
    // Line of sight: from each kept cell, a far cell in clear view, found by doubling the
    // look-ahead while the view is clear and halving back between the last clear and the
    // first blocked one (not always the furthest visible, but O(log n) checks per cell).
    const std::size_t last = cells->size() - 1;
    for (std::size_t i = 0; i < last;) {
      std::size_t ok = i + 1, bad = last + 1;
      for (std::size_t step = 2; ok < last; step *= 2) {
        const std::size_t j = std::min(last, i + step);
        if (!clear(field, (*cells)[i], (*cells)[j])) {
          bad = j;
          break;
        }
        ok = j;
      }
      while (bad - ok > 1) {
        const std::size_t j = ok + (bad - ok) / 2;
        if (clear(field, (*cells)[i], (*cells)[j])) ok = j;
        else bad = j;
      }
      kept.push_back((*cells)[ok]);
      i = ok;
    }
  } else {
    kept = *cells;
  }
  for (const Cell& c : kept) {
    Point p = centre(c);
    for (double& x : p) x *= cell_size;
    out.points.push_back(p);
  }
  for (std::size_t i = 1; i < out.points.size(); ++i) out.length += distance(out.points[i - 1], out.points[i]);
  out.cost *= cell_size;
  return out;
}

}  // namespace vola::raycast
