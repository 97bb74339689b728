// Path planning on a real survey: vola's planner (raycast::plan_path, what `vola plan`
// runs) against a straightforward A* over a dense grid of the same resolution, in the
// same run (issue 5, point 6).
//
// The scene: one .vol file, e.g. `vola convert pdal_autzen_trim.las autzen.vol
// --voxel-size 1 --depth 8`. Its tree spans 4^depth voxels a side (65,536 at depth 8: a
// dense grid of the whole volume would hold 2.8e14 cells), so the dense peer covers only
// the box of the occupied voxels widened by --margin voxels on every side (default: the
// robot radius + 2), clipped to the volume. vola plans in the whole volume.
//
// Start and goal: unless --from/--to give them (grid coordinates), the first free cell
// (no voxel within the radius) above the ground of a column near two opposite corners of
// the occupied box (at 4 % / 10 % and 96 % / 90 % of its x / y extent), so the path
// crosses the scene near the ground, among trees and buildings.
//
// The planners, each run --reps times in a forked child (time, and the child's peak RSS
// growth from a fresh VmHWM), interleaved run by run:
//   vola A*         plan_path with the radius, finest level, smoothing off: the A* alone
//                   (its state per brick of 16^3 cells reached, the clearance field
//                   computed a brick at a time);
//   vola plan       plan_path with `vola plan`'s defaults (smoothing on): what the CLI does
//                   after opening the file;
//   vola hier.      plan_path with hierarchical = true (`vola plan --hierarchical`):
//                   a route over free bricks first, cost not guaranteed optimal;
//   dense A*        std::vector<uint8_t> occupancy of the box filled from the tree's voxels,
//                   inflated by the same sphere rule (a cell is blocked when a voxel's
//                   closed cube lies within the radius of the cell's centre, as
//                   Collider::sphere decides), then A* with 26 neighbours (a diagonal
//                   move only when every cell of the box it spans is free, as vola's),
//                   Euclidean costs and heuristic, g in a std::vector<double>, the parent as a direction
//                   byte, a binary heap as the open list. Its time includes filling and
//                   inflating the grid; the search alone is shown too.
// Checks before any figure is printed: the dense inflation agrees with Collider::sphere on
// --samples random cells of the box and on every cell of both paths; each path is made of
// 26-neighbour steps over free cells whose costs add up to the reported cost; vola's A* path
// stays inside the dense box (so both searched the same graph: the costs must be equal up
// to the rounding of a sum of square roots, checked to 1e-9 relative).
//
// usage: vola_plan_bench FILE.vol [--radius R (world units)] [--reps K] [--margin M]
//                        [--from X Y Z --to X Y Z (grid)] [--samples N]
// Exit status 0 when the checks pass, 1 otherwise.
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <functional>
#include <limits>
#include <optional>
#include <queue>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "vola/error.hpp"
#include "vola/file.hpp"
#include "vola/raycast/collision.hpp"
#include "vola/raycast/path_planner.hpp"

namespace {

using vola::Point;
using vola::Tree;
using vola::raycast::Collider;

// --- measuring in a child -----------------------------------------------------------------
long status_kib(const char* field) {
  std::ifstream in("/proc/self/status");
  std::string line;
  while (std::getline(in, line))
    if (line.rfind(field, 0) == 0) return std::stol(line.substr(std::strlen(field)));
  return -1;
}

void reset_peak_rss() {
  std::ofstream clear("/proc/self/clear_refs");
  clear << "5";  // VmHWM := VmRSS (Linux >= 4.0)
}

struct Outcome {
  double seconds = 0;         // the whole call
  double search_seconds = 0;  // dense: the A* alone
  double peak_mib = 0;        // peak RSS growth in the child
  double cost = 0;            // A* cost in voxels
  std::uint64_t expanded = 0;
  std::uint64_t waypoints = 0;
  double structure_mib = 0;   // dense: the arrays' bytes
  // The checks' child: dense cost, cells checked, vola path cells outside the box, failures.
  double dense_cost = 0;
  std::uint64_t checked = 0, outside = 0, failures = 0;
};

// Runs op in a forked child (same heap as the parent at the fork) and returns what it measured.
Outcome in_child(const std::function<Outcome()>& op) {
  int fd[2];
  if (pipe(fd) != 0) throw std::runtime_error("pipe");
  std::fflush(stdout);
  const pid_t pid = fork();
  if (pid < 0) throw std::runtime_error("fork");
  if (pid == 0) {
    close(fd[0]);
    reset_peak_rss();
    const long before = status_kib("VmRSS:");
    Outcome r;
    const auto t0 = std::chrono::steady_clock::now();
    try {
      r = op();
    } catch (const std::exception& e) {  // must not unwind into the parent's main()
      std::fprintf(stderr, "vola_plan_bench: in a measured child: %s\n", e.what());
      _exit(1);
    }
    r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    r.peak_mib = static_cast<double>(status_kib("VmHWM:") - before) / 1024.0;
    std::fflush(stdout);
    if (write(fd[1], &r, sizeof r) != static_cast<ssize_t>(sizeof r)) _exit(1);
    _exit(0);
  }
  close(fd[1]);
  Outcome r;
  const bool ok = read(fd[0], &r, sizeof r) == static_cast<ssize_t>(sizeof r);
  close(fd[0]);
  int status = 0;
  waitpid(pid, &status, 0);
  if (!ok || !WIFEXITED(status) || WEXITSTATUS(status) != 0) throw std::runtime_error("a measured child failed");
  return r;
}

// --- the dense peer -------------------------------------------------------------------------
struct Box3 {
  std::int64_t lo[3], hi[3];  // inclusive
  std::int64_t n(int a) const { return hi[a] - lo[a] + 1; }
  std::uint64_t cells() const { return static_cast<std::uint64_t>(n(0) * n(1) * n(2)); }
  bool inside(std::int64_t x, std::int64_t y, std::int64_t z) const {
    return x >= lo[0] && x <= hi[0] && y >= lo[1] && y <= hi[1] && z >= lo[2] && z <= hi[2];
  }
};

// Offsets (dx, dy, dz) from an occupied voxel to the cells it blocks: the voxel's closed
// cube [0,1]^3 lies within `radius` of the centre (d + 0.5) of cell d. Per axis the gap is
// max(0, |d| - 0.5), the same half-integer arithmetic as Collider::sphere (exact in doubles).
std::vector<std::array<int, 3>> sphere_offsets(double radius) {
  const int reach = static_cast<int>(std::floor(radius + 0.5)) + 1;
  const double r2 = radius * radius;
  std::vector<std::array<int, 3>> out;
  for (int dz = -reach; dz <= reach; ++dz)
    for (int dy = -reach; dy <= reach; ++dy)
      for (int dx = -reach; dx <= reach; ++dx) {
        double d2 = 0;
        for (const int d : {dx, dy, dz}) {
          const double gap = std::max(0.0, std::abs(d) - 0.5);
          d2 += gap * gap;
        }
        if (d2 <= r2) out.push_back({dx, dy, dz});
      }
  return out;
}

class DenseGrid {
 public:
  DenseGrid(const Tree& tree, const Box3& box, double radius) : box_(box), blocked_(box.cells(), 0) {
    const auto offsets = sphere_offsets(radius);
    std::vector<std::int64_t> deltas;
    for (const auto& o : offsets) deltas.push_back(o[0] + nx() * (o[1] + ny() * o[2]));
    const std::int64_t reach = static_cast<std::int64_t>(std::floor(radius + 0.5)) + 1;
    tree.for_each_voxel([&](const vola::Voxel& v) {
      const std::int64_t x = v.x, y = v.y, z = v.z;
      // Voxels whose sphere reaches the box's border need per-cell checks; the rest do not.
      const bool interior = x - reach >= box_.lo[0] && x + reach <= box_.hi[0] && y - reach >= box_.lo[1] &&
                            y + reach <= box_.hi[1] && z - reach >= box_.lo[2] && z + reach <= box_.hi[2];
      if (interior) {
        const std::int64_t at = index(x, y, z);
        for (const std::int64_t d : deltas) blocked_[static_cast<std::size_t>(at + d)] = 1;
      } else {
        for (const auto& o : offsets)
          if (box_.inside(x + o[0], y + o[1], z + o[2])) blocked_[static_cast<std::size_t>(index(x + o[0], y + o[1], z + o[2]))] = 1;
      }
    });
  }
  std::int64_t nx() const { return box_.n(0); }
  std::int64_t ny() const { return box_.n(1); }
  std::int64_t index(std::int64_t x, std::int64_t y, std::int64_t z) const {
    return (x - box_.lo[0]) + nx() * ((y - box_.lo[1]) + ny() * (z - box_.lo[2]));
  }
  bool blocked(std::int64_t x, std::int64_t y, std::int64_t z) const { return blocked_[static_cast<std::size_t>(index(x, y, z))]; }
  const Box3& box() const { return box_; }
  std::size_t bytes() const { return blocked_.size(); }

  struct Result {
    double cost = -1;  // -1: unreachable
    std::uint64_t expanded = 0;
    std::vector<std::array<std::int64_t, 3>> path;
    std::size_t bytes = 0;
  };
  // A* from start to goal (global grid coordinates, inside the box).
  Result astar(const std::array<std::int64_t, 3>& start, const std::array<std::int64_t, 3>& goal) const {
    Result out;
    const std::size_t cells = blocked_.size();
    std::vector<double> g(cells, std::numeric_limits<double>::infinity());
    std::vector<std::uint8_t> parent(cells, 255);  // direction index 0..25 of the step into the cell
    int ddx[26], ddy[26], ddz[26];
    std::int64_t dindex[26];
    double step[26];
    std::vector<std::int64_t> spanned[26];  // the other cells of the box a move spans: free too (no corner cutting)
    int k = 0;
    for (int dz = -1; dz <= 1; ++dz)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          if (!dx && !dy && !dz) continue;
          ddx[k] = dx, ddy[k] = dy, ddz[k] = dz;
          dindex[k] = dx + nx() * (dy + ny() * dz);
          step[k] = std::sqrt(static_cast<double>(dx * dx + dy * dy + dz * dz));
          for (int bz = std::min(0, dz); bz <= std::max(0, dz); ++bz)
            for (int by = std::min(0, dy); by <= std::max(0, dy); ++by)
              for (int bx = std::min(0, dx); bx <= std::max(0, dx); ++bx)
                if ((bx || by || bz) && !(bx == dx && by == dy && bz == dz))
                  spanned[k].push_back(bx + nx() * (by + ny() * bz));
          ++k;
        }
    const double gx = static_cast<double>(goal[0]) + 0.5, gy = static_cast<double>(goal[1]) + 0.5,
                 gz = static_cast<double>(goal[2]) + 0.5;
    auto h = [&](std::int64_t x, std::int64_t y, std::int64_t z) {
      const double ex = static_cast<double>(x) + 0.5 - gx, ey = static_cast<double>(y) + 0.5 - gy,
                   ez = static_cast<double>(z) + 0.5 - gz;
      return std::sqrt(ex * ex + ey * ey + ez * ez);
    };
    struct Open {
      double f, g;
      std::int64_t at;
      bool operator>(const Open& o) const { return f > o.f; }
    };
    std::vector<Open> heap_storage;
    heap_storage.reserve(1 << 16);
    std::priority_queue<Open, std::vector<Open>, std::greater<>> open(std::greater<>{}, std::move(heap_storage));
    const std::int64_t s = index(start[0], start[1], start[2]), t = index(goal[0], goal[1], goal[2]);
    g[static_cast<std::size_t>(s)] = 0;
    open.push({h(start[0], start[1], start[2]), 0.0, s});
    std::size_t peak_open = 1;
    while (!open.empty()) {
      const Open top = open.top();
      open.pop();
      if (top.g > g[static_cast<std::size_t>(top.at)]) continue;  // stale
      ++out.expanded;
      const std::int64_t lx = top.at % nx(), ly = (top.at / nx()) % ny(), lz = top.at / (nx() * ny());
      if (top.at == t) {
        out.cost = top.g;
        std::int64_t x = lx + box_.lo[0], y = ly + box_.lo[1], z = lz + box_.lo[2];
        for (std::int64_t at = t;;) {
          out.path.push_back({x, y, z});
          if (at == s) break;
          const int d = parent[static_cast<std::size_t>(at)];
          x -= ddx[d], y -= ddy[d], z -= ddz[d], at -= dindex[d];
        }
        std::reverse(out.path.begin(), out.path.end());
        break;
      }
      const bool edge = lx == 0 || ly == 0 || lz == 0 || lx == nx() - 1 || ly == ny() - 1 || lz == box_.n(2) - 1;
      for (int d = 0; d < 26; ++d) {
        if (edge && !(lx + ddx[d] >= 0 && lx + ddx[d] < nx() && ly + ddy[d] >= 0 && ly + ddy[d] < ny() &&
                      lz + ddz[d] >= 0 && lz + ddz[d] < box_.n(2)))
          continue;
        const std::int64_t n = top.at + dindex[d];
        const auto un = static_cast<std::size_t>(n);
        if (blocked_[un]) continue;
        bool cut = false;
        for (const std::int64_t o : spanned[d]) cut = cut || blocked_[static_cast<std::size_t>(top.at + o)];
        if (cut) continue;
        const double ng = top.g + step[d];
        if (ng >= g[un]) continue;
        g[un] = ng;
        parent[un] = static_cast<std::uint8_t>(d);
        open.push({ng + h(lx + ddx[d] + box_.lo[0], ly + ddy[d] + box_.lo[1], lz + ddz[d] + box_.lo[2]), ng, n});
      }
      peak_open = std::max(peak_open, open.size());
    }
    out.bytes = cells * (sizeof(double) + 1) + peak_open * sizeof(Open);
    return out;
  }

 private:
  Box3 box_;
  std::vector<std::uint8_t> blocked_;
};

// --- choosing the endpoints -----------------------------------------------------------------
// The first cell with no voxel within the radius, above the lowest voxel of a column near
// (x, y) (columns tried outward in rings); nullopt when none within 32 cells.
std::optional<std::array<std::int64_t, 3>> free_above_ground(const Tree& tree, const Collider& collider,
                                                             const Box3& occupied, const Box3& dense, double radius,
                                                             std::int64_t x0, std::int64_t y0) {
  for (std::int64_t ring = 0; ring <= 32; ++ring)
    for (std::int64_t dy = -ring; dy <= ring; ++dy)
      for (std::int64_t dx = -ring; dx <= ring; ++dx) {
        if (std::max(std::abs(dx), std::abs(dy)) != ring) continue;
        const std::int64_t x = x0 + dx, y = y0 + dy;
        if (!occupied.inside(x, y, occupied.lo[2])) continue;
        std::int64_t ground = -1;
        for (std::int64_t z = occupied.lo[2]; z <= occupied.hi[2] && ground < 0; ++z)
          if (tree.contains(static_cast<std::uint32_t>(x), static_cast<std::uint32_t>(y), static_cast<std::uint32_t>(z)))
            ground = z;
        if (ground < 0) continue;
        for (std::int64_t z = ground + 1; z < dense.hi[2]; ++z)
          if (!collider.sphere({static_cast<double>(x) + 0.5, static_cast<double>(y) + 0.5, static_cast<double>(z) + 0.5},
                               radius))
            return std::array<std::int64_t, 3>{x, y, z};
      }
  return std::nullopt;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

}  // namespace

int main(int argc, char** argv) try {
  if (argc < 2) {
    std::fprintf(stderr,
                 "usage: %s FILE.vol [--radius R] [--reps K] [--margin M] [--from X Y Z --to X Y Z] [--samples N]\n",
                 argv[0]);
    return 2;
  }
  const std::string file = argv[1];
  double radius_world = 0;
  int reps = 5;
  std::int64_t margin = -1;
  std::uint64_t samples = 200000;
  std::optional<Point> from_arg, to_arg;
  for (int i = 2; i < argc; ++i) {
    const std::string a = argv[i];
    auto need = [&](int n) {
      if (i + n >= argc) throw std::runtime_error(a + " needs " + std::to_string(n) + " value(s)");
    };
    if (a == "--radius") need(1), radius_world = std::stod(argv[++i]);
    else if (a == "--reps") need(1), reps = std::max(1, std::stoi(argv[++i]));
    else if (a == "--margin") need(1), margin = std::stoll(argv[++i]);
    else if (a == "--samples") need(1), samples = std::stoull(argv[++i]);
    else if (a == "--from" || a == "--to") {
      need(3);
      Point p{std::stod(argv[i + 1]), std::stod(argv[i + 2]), std::stod(argv[i + 3])};
      i += 3;
      (a == "--from" ? from_arg : to_arg) = p;
    } else throw std::runtime_error("unknown argument " + a);
  }

  const Tree tree = vola::open_mapped(file);
  const vola::Frame frame = tree.frame();
  const double radius = radius_world / frame.voxel_size;  // in voxels, as `vola plan --radius` converts
  if (tree.empty()) throw std::runtime_error(file + " has no voxels");
  const Collider collider(tree);

  Box3 occupied{{INT64_MAX, INT64_MAX, INT64_MAX}, {-1, -1, -1}};
  tree.for_each_voxel([&](const vola::Voxel& v) {
    const std::int64_t c[3] = {v.x, v.y, v.z};
    for (int a = 0; a < 3; ++a) occupied.lo[a] = std::min(occupied.lo[a], c[a]), occupied.hi[a] = std::max(occupied.hi[a], c[a]);
  });
  if (margin < 0) margin = static_cast<std::int64_t>(std::ceil(radius)) + 2;
  const auto side = static_cast<std::int64_t>(tree.side());
  Box3 dense_box = occupied;
  for (int a = 0; a < 3; ++a)
    dense_box.lo[a] = std::max<std::int64_t>(0, occupied.lo[a] - margin),
    dense_box.hi[a] = std::min<std::int64_t>(side - 1, occupied.hi[a] + margin);

  std::array<std::int64_t, 3> start{}, goal{};
  if (from_arg && to_arg) {
    for (int a = 0; a < 3; ++a)
      start[a] = static_cast<std::int64_t>(std::floor((*from_arg)[a])), goal[a] = static_cast<std::int64_t>(std::floor((*to_arg)[a]));
  } else {
    auto at = [&](int a, double f) {
      return occupied.lo[a] + static_cast<std::int64_t>(std::floor(f * static_cast<double>(occupied.n(a) - 1)));
    };
    const auto s = free_above_ground(tree, collider, occupied, dense_box, radius, at(0, 0.04), at(1, 0.10));
    const auto g = free_above_ground(tree, collider, occupied, dense_box, radius, at(0, 0.96), at(1, 0.90));
    if (!s || !g) throw std::runtime_error("no free cell above the ground near the chosen corners: give --from/--to");
    start = *s, goal = *g;
  }
  for (const auto& p : {start, goal})
    if (!dense_box.inside(p[0], p[1], p[2])) throw std::runtime_error("start and goal must lie inside the dense box");
  auto centre = [](const std::array<std::int64_t, 3>& c) {
    return Point{static_cast<double>(c[0]) + 0.5, static_cast<double>(c[1]) + 0.5, static_cast<double>(c[2]) + 0.5};
  };
  const Point start_point = centre(start), goal_point = centre(goal);

  std::printf("## Path planning: vola against a dense-grid A* (%s)\n\n", file.c_str());
  std::printf("tree: depth %d (%lld^3 voxels), voxel size %g, %llu voxels; occupied box %lld x %lld x %lld\n",
              tree.depth(), static_cast<long long>(side), frame.voxel_size,
              static_cast<unsigned long long>(tree.voxel_count()), static_cast<long long>(occupied.n(0)),
              static_cast<long long>(occupied.n(1)), static_cast<long long>(occupied.n(2)));
  std::printf("dense grid: the occupied box + %lld voxels a side = %lld x %lld x %lld = %.4g cells "
              "(the whole volume would be %.3g cells)\n",
              static_cast<long long>(margin), static_cast<long long>(dense_box.n(0)),
              static_cast<long long>(dense_box.n(1)), static_cast<long long>(dense_box.n(2)),
              static_cast<double>(dense_box.cells()), std::pow(static_cast<double>(side), 3));
  std::printf("robot radius %g (world) = %g voxels; start (%lld, %lld, %lld), goal (%lld, %lld, %lld) (grid), "
              "%.1f voxels apart; %d runs each, medians\n\n",
              radius_world, radius, static_cast<long long>(start[0]), static_cast<long long>(start[1]),
              static_cast<long long>(start[2]), static_cast<long long>(goal[0]), static_cast<long long>(goal[1]),
              static_cast<long long>(goal[2]),
              std::hypot(goal_point[0] - start_point[0], goal_point[1] - start_point[1], goal_point[2] - start_point[2]),
              reps);

  // --- checks (untimed), in a child too: the parent's heap must not grow, or the measured
  // children would reuse its freed pages and show no growth ---
  bool ok = true;
  auto fail = [&](const std::string& why) {
    std::printf("CHECK FAILED: %s\n", why.c_str());
    ok = false;
  };
  const Outcome checks = in_child([&] {
    Outcome result;
    auto fail_check = [&](const std::string& why) {
      std::printf("CHECK FAILED: %s\n", why.c_str());
      ++result.failures;
    };
    vola::raycast::PlanOptions astar_options;
    astar_options.radius = radius;
    astar_options.smooth = false;
    const vola::raycast::PlannedPath vola_path = vola::raycast::plan_path(tree, start_point, goal_point, astar_options);
    std::uint64_t inflation_checked = 0, outside = 0;
    const DenseGrid dense(tree, dense_box, radius);
    const DenseGrid::Result dense_path = dense.astar(start, goal);
    if (dense_path.cost < 0) fail_check("the dense A* found no path");
    auto blocked_by_collider = [&](std::int64_t x, std::int64_t y, std::int64_t z) {
      return collider.sphere(centre({x, y, z}), radius);
    };
    std::mt19937_64 random(5);
    for (std::uint64_t i = 0; i < samples; ++i) {
      std::int64_t c[3];
      for (int a = 0; a < 3; ++a)
        c[a] = dense_box.lo[a] + static_cast<std::int64_t>(random() % static_cast<std::uint64_t>(dense_box.n(a)));
      if (dense.blocked(c[0], c[1], c[2]) != blocked_by_collider(c[0], c[1], c[2]))
        fail_check("inflation differs at a sampled cell");
      ++inflation_checked;
    }
    // A path: consecutive 26-neighbours, free cells, costs adding up.
    auto check_path = [&](const char* name, const std::vector<std::array<std::int64_t, 3>>& path, double cost) {
      if (path.empty() || path.front() != start || path.back() != goal) return fail_check(std::string(name) + ": wrong ends");
      double sum = 0;
      for (std::size_t i = 0; i < path.size(); ++i) {
        const auto& c = path[i];
        if (blocked_by_collider(c[0], c[1], c[2])) fail_check(std::string(name) + ": a cell closer than the radius to a voxel");
        if (dense_box.inside(c[0], c[1], c[2])) {
          if (dense.blocked(c[0], c[1], c[2])) fail_check(std::string(name) + ": a cell blocked in the dense grid");
          ++inflation_checked;
        } else {
          ++outside;
        }
        if (i) {
          std::int64_t d2 = 0;
          for (int a = 0; a < 3; ++a) {
            const std::int64_t d = c[a] - path[i - 1][a];
            if (d < -1 || d > 1) fail_check(std::string(name) + ": not a 26-neighbour step");
            d2 += d * d;
          }
          if (!d2) fail_check(std::string(name) + ": a repeated cell");
          sum += std::sqrt(static_cast<double>(d2));
        }
      }
      if (std::abs(sum - cost) > 1e-9 * std::max(1.0, cost)) fail_check(std::string(name) + ": step costs do not add up");
    };
    std::vector<std::array<std::int64_t, 3>> vola_cells;
    for (const Point& p : vola_path.points)
      vola_cells.push_back({static_cast<std::int64_t>(std::floor(p[0])), static_cast<std::int64_t>(std::floor(p[1])),
                            static_cast<std::int64_t>(std::floor(p[2]))});
    check_path("vola", vola_cells, vola_path.cost);
    check_path("dense", dense_path.path, dense_path.cost);
    std::printf("checks: inflation identical to Collider::sphere on %llu cells (random + both paths); "
                "vola's path has %llu cells outside the dense box; both paths are free 26-neighbour steps\n",
                static_cast<unsigned long long>(inflation_checked), static_cast<unsigned long long>(outside));
    result.cost = vola_path.cost;
    result.dense_cost = dense_path.cost;
    result.checked = inflation_checked;
    result.outside = outside;
    return result;
  });
  if (checks.failures) fail(std::to_string(checks.failures) + " check(s) failed in the checking child");
  const double vola_cost = checks.cost;
  const double dense_cost = checks.dense_cost;
  const std::uint64_t outside = checks.outside;
  const double diff = vola_cost - dense_cost;
  std::printf("A* cost: vola %.12g, dense %.12g voxels (difference %.3g; %.6g world units)\n", vola_cost,
              dense_cost, diff, vola_cost * frame.voxel_size);
  if (outside == 0 && std::abs(diff) > 1e-9 * std::max(1.0, dense_cost)) fail("the optimal costs differ");
  if (outside > 0 && diff > 1e-9 * std::max(1.0, dense_cost))
    fail("vola's cost is above the dense grid's although it searches a superset");

  // --- timed runs, interleaved ---
  struct Planner {
    const char* name;
    std::function<Outcome()> run;
    std::vector<Outcome> runs;
  };
  auto vola_run = [&](bool smooth, bool hierarchical) {
    return [&, smooth, hierarchical] {
      vola::raycast::PlanOptions o;
      o.radius = radius;
      o.smooth = smooth;
      o.hierarchical = hierarchical;
      const auto p = vola::raycast::plan_path(tree, start_point, goal_point, o);
      Outcome r;
      r.cost = p.cost;
      r.expanded = p.expanded;
      r.waypoints = p.points.size();
      return r;
    };
  };
  std::vector<Planner> planners{
      {"vola A* (plan_path, smoothing off)", vola_run(false, false), {}},
      {"vola plan (plan_path defaults: smoothing on)", vola_run(true, false), {}},
      {"vola plan --hierarchical (smoothing on)", vola_run(true, true), {}},
      {"dense A* (uint8 grid: fill + inflate + search)",
       [&] {
         const DenseGrid dense(tree, dense_box, radius);
         const auto t1 = std::chrono::steady_clock::now();
         const DenseGrid::Result p = dense.astar(start, goal);
         Outcome r;
         r.search_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t1).count();
         r.cost = p.cost;
         r.expanded = p.expanded;
         r.waypoints = p.path.size();
         r.structure_mib = static_cast<double>(dense.bytes() + p.bytes) / 1048576.0;
         return r;
       },
       {}},
  };
  for (int rep = 0; rep < reps; ++rep)
    for (Planner& p : planners) p.runs.push_back(in_child(p.run));

  std::printf("\n| planner | time (s) | of which A* search (s) | peak memory (MiB) | cells expanded | A* cost (voxels) | waypoints |\n");
  std::printf("|---|---|---|---|---|---|---|\n");
  std::vector<double> medians;
  for (const Planner& p : planners) {
    std::vector<double> t, s, m;
    for (const Outcome& r : p.runs) {
      t.push_back(r.seconds), s.push_back(r.search_seconds), m.push_back(r.peak_mib);
      if (r.cost != p.runs[0].cost || r.expanded != p.runs[0].expanded) fail(std::string(p.name) + ": runs disagree");
    }
    const Outcome& first = p.runs[0];
    char search[32] = "-";
    if (first.search_seconds > 0) std::snprintf(search, sizeof search, "%.3g", median(s));
    char memory[64];
    std::snprintf(memory, sizeof memory, "%.1f", median(m));
    if (first.structure_mib > 0)
      std::snprintf(memory, sizeof memory, "%.1f (arrays %.1f)", median(m), first.structure_mib);
    std::printf("| %s | %.3g | %s | %s | %llu | %.12g | %llu |\n", p.name, median(t), search, memory,
                static_cast<unsigned long long>(first.expanded), first.cost,
                static_cast<unsigned long long>(first.waypoints));
    medians.push_back(median(t));
  }
  std::printf("\nvola A* / dense A* time: %.2fx; costs %s (vola %.12g, dense %.12g)\n", medians[0] / medians[3],
              std::abs(diff) <= 1e-9 * std::max(1.0, dense_cost) ? "equal" : "DIFFER", vola_cost, dense_cost);
  if (planners[2].runs[0].expanded == planners[0].runs[0].expanded)
    std::printf("note: --hierarchical expanded exactly the full search's cells: its coarse plan (cells of 16^3 "
                "voxels, occupied when any voxel is) failed, so it fell back to the full search\n");
  if (planners[2].runs[0].cost > dense_cost + 1e-9 * std::max(1.0, dense_cost))
    std::printf("note: the hierarchical plan's cost is %.6g%% above the optimum (it searches a corridor)\n",
                100.0 * (planners[2].runs[0].cost / dense_cost - 1.0));
  std::printf("%s\n", ok ? "all checks passed" : "CHECKS FAILED");
  return ok ? 0 : 1;
} catch (const std::exception& e) {
  std::fprintf(stderr, "vola_plan_bench: %s\n", e.what());
  return 1;
}
