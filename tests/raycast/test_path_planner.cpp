// A* against a brute-force Dijkstra over a dense array of small grids (with obstacles and
// inflation, no corner cutting), paths whose every leg keeps the sphere clear (checked
// voxel by voxel along the leg), coarse and hierarchical plans, and errors.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <queue>
#include <random>

#include "vola/builder.hpp"
#include "vola/error.hpp"
#include "vola/raycast/path_planner.hpp"
#include "plan_checks.hpp"

namespace {

using vola::Point;
using vola::raycast::PlanOptions;
using vola::raycast::plan_path;

// Random walls with gaps in a grid of side 4^depth.
vola::Tree maze(std::uint64_t seed, int depth) {
  std::mt19937_64 rng(seed);
  const std::uint32_t side = vola::side_of(depth);
  std::vector<vola::Voxel> voxels;
  for (int wall = 0; wall < 3; ++wall) {
    const std::uint32_t x = 2 + static_cast<std::uint32_t>(rng() % (side - 4));
    for (std::uint32_t y = 0; y < side; ++y)
      for (std::uint32_t z = 0; z < side; ++z)
        if (rng() % 10 != 0) voxels.push_back({x, y, z});  // 10% holes
  }
  for (int i = 0; i < static_cast<int>(side * side); ++i)
    voxels.push_back({static_cast<std::uint32_t>(rng() % side), static_cast<std::uint32_t>(rng() % side),
                      static_cast<std::uint32_t>(rng() % side)});
  return vola::build_from_voxels(voxels, depth);
}

// Is a voxel centre free for a robot of `radius` < 2: the nearest point of every occupied
// voxel within two cells, from a dense occupancy array.
std::vector<char> brute_free(const vola::Tree& tree, double radius) {
  const std::int64_t side = tree.side();
  auto index = [&](std::int64_t x, std::int64_t y, std::int64_t z) { return static_cast<std::size_t>((z * side + y) * side + x); };
  std::vector<char> occupied(static_cast<std::size_t>(side * side * side), 0), free(occupied.size(), 1);
  tree.for_each_voxel([&](const vola::Voxel& v) { occupied[index(v.x, v.y, v.z)] = 1; });
  for (std::int64_t z = 0; z < side; ++z)
    for (std::int64_t y = 0; y < side; ++y)
      for (std::int64_t x = 0; x < side; ++x)
        for (std::int64_t oz = std::max<std::int64_t>(0, z - 2); oz <= std::min(side - 1, z + 2); ++oz)
          for (std::int64_t oy = std::max<std::int64_t>(0, y - 2); oy <= std::min(side - 1, y + 2); ++oy)
            for (std::int64_t ox = std::max<std::int64_t>(0, x - 2); ox <= std::min(side - 1, x + 2); ++ox) {
              if (!occupied[index(ox, oy, oz)]) continue;
              const double c[3] = {double(x) + 0.5, double(y) + 0.5, double(z) + 0.5};
              const double o[3] = {double(ox), double(oy), double(oz)};
              double d2 = 0;
              for (int a = 0; a < 3; ++a) {
                const double n = std::clamp(c[a], o[a], o[a] + 1);
                d2 += (c[a] - n) * (c[a] - n);
              }
              if (d2 <= radius * radius) free[index(x, y, z)] = 0;
            }
  return free;
}

// Dijkstra over the dense array; +inf when unreachable. A diagonal move needs every cell
// of the box it spans free.
double dijkstra(const std::vector<char>& free, std::int64_t side, std::array<std::int64_t, 3> s,
                std::array<std::int64_t, 3> g) {
  auto index = [&](std::int64_t x, std::int64_t y, std::int64_t z) { return static_cast<std::size_t>((z * side + y) * side + x); };
  std::vector<double> dist(free.size(), std::numeric_limits<double>::infinity());
  using Item = std::pair<double, std::size_t>;
  std::priority_queue<Item, std::vector<Item>, std::greater<>> q;
  dist[index(s[0], s[1], s[2])] = 0;
  q.push({0, index(s[0], s[1], s[2])});
  while (!q.empty()) {
    const auto [d, i] = q.top();
    q.pop();
    if (d > dist[i]) continue;
    const auto x = static_cast<std::int64_t>(i % side), y = static_cast<std::int64_t>(i / side % side),
               z = static_cast<std::int64_t>(i / side / side);
    for (int dz = -1; dz <= 1; ++dz)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const std::int64_t nx = x + dx, ny = y + dy, nz = z + dz;
          if ((!dx && !dy && !dz) || nx < 0 || ny < 0 || nz < 0 || nx >= side || ny >= side || nz >= side) continue;
          const std::size_t n = index(nx, ny, nz);
          const double nd = d + std::sqrt(double(dx * dx + dy * dy + dz * dz));
          bool spanned_free = true;
          for (std::int64_t bz = std::min(z, nz); bz <= std::max(z, nz); ++bz)
            for (std::int64_t by = std::min(y, ny); by <= std::max(y, ny); ++by)
              for (std::int64_t bx = std::min(x, nx); bx <= std::max(x, nx); ++bx)
                spanned_free = spanned_free && free[index(bx, by, bz)];
          if (spanned_free && nd < dist[n]) {
            dist[n] = nd;
            q.push({nd, n});
          }
        }
  }
  return dist[index(g[0], g[1], g[2])];
}

TEST(PathPlanner, CostEqualsDijkstraOnSmallGrids) {
  int compared = 0, unreachable = 0;
  for (std::uint64_t seed = 1; seed <= 8; ++seed) {
    const int depth = seed % 2 ? 2 : 3;
    const vola::Tree tree = maze(seed, depth);
    const std::int64_t side = tree.side();
    for (const double radius : {0.0, 0.9, 1.5}) {
      const auto free = brute_free(tree, radius);
      std::mt19937_64 rng(seed * 31);
      for (int trial = 0; trial < 6; ++trial) {
        std::array<std::int64_t, 3> s{}, g{};
        auto random_free = [&](std::array<std::int64_t, 3>& c) {
          do {
            for (auto& x : c) x = static_cast<std::int64_t>(rng() % static_cast<std::uint64_t>(side));
          } while (!free[static_cast<std::size_t>((c[2] * side + c[1]) * side + c[0])]);
        };
        random_free(s);
        random_free(g);
        const double expected = dijkstra(free, side, s, g);
        const Point from{double(s[0]) + 0.5, double(s[1]) + 0.5, double(s[2]) + 0.5},
            to{double(g[0]) + 0.5, double(g[1]) + 0.5, double(g[2]) + 0.5};
        PlanOptions options;
        options.radius = radius;
        if (std::isinf(expected)) {
          EXPECT_THROW(plan_path(tree, from, to, options), vola::InvalidArgument);
          ++unreachable;
          continue;
        }
        const auto path = plan_path(tree, from, to, options);
        EXPECT_NEAR(path.cost, expected, 1e-9) << "seed " << seed << " radius " << radius;
        EXPECT_LE(path.length, path.cost + 1e-9);  // smoothing only shortens
        EXPECT_EQ(path.points.front(), from);
        EXPECT_EQ(path.points.back(), to);
        // Every leg keeps the robot clear, smoothed or not.
        EXPECT_EQ(vola::test::legs_clear(tree, nullptr, path.points, radius), "") << "seed " << seed;
        options.smooth = false;
        const auto raw = plan_path(tree, from, to, options);
        EXPECT_NEAR(raw.cost, expected, 1e-9);
        EXPECT_NEAR(raw.length, raw.cost, 1e-9);  // the cells' steps, one by one
        EXPECT_EQ(vola::test::legs_clear(tree, nullptr, raw.points, radius), "") << "seed " << seed;
        ++compared;
      }
    }
  }
  EXPECT_GT(compared, 50);
  EXPECT_GT(unreachable + compared, 90);
}

// With `known`, a cell is free only when besides no voxel within the radius is unknown
// (cells off the grid are unknown): the brute force over the dense arrays.
std::vector<char> brute_known_free(const vola::Tree& known, const std::vector<char>& free, double radius) {
  const std::int64_t side = known.side();
  std::vector<char> out = free;
  for (std::int64_t z = 0; z < side; ++z)
    for (std::int64_t y = 0; y < side; ++y)
      for (std::int64_t x = 0; x < side; ++x)
        for (std::int64_t oz = z - 2; oz <= z + 2; ++oz)
          for (std::int64_t oy = y - 2; oy <= y + 2; ++oy)
            for (std::int64_t ox = x - 2; ox <= x + 2; ++ox) {
              const double c[3] = {double(x) + 0.5, double(y) + 0.5, double(z) + 0.5};
              const double o[3] = {double(ox), double(oy), double(oz)};
              double d2 = 0;
              for (int a = 0; a < 3; ++a) {
                const double n = std::clamp(c[a], o[a], o[a] + 1);
                d2 += (c[a] - n) * (c[a] - n);
              }
              if (d2 > radius * radius) continue;
              const bool inside = ox >= 0 && oy >= 0 && oz >= 0 && ox < side && oy < side && oz < side;
              if (!inside || !known.contains(vola::Voxel{static_cast<std::uint32_t>(ox), static_cast<std::uint32_t>(oy),
                                                         static_cast<std::uint32_t>(oz)}))
                out[static_cast<std::size_t>((z * side + y) * side + x)] = 0;
            }
  return out;
}

TEST(PathPlanner, UnknownSpaceIsAnObstacleWithKnown) {
  int compared = 0, unreachable = 0, longer = 0;
  for (std::uint64_t seed = 1; seed <= 6; ++seed) {
    const vola::Tree tree = maze(seed, 2);
    const std::int64_t side = tree.side();
    // Known: everything but a few random boxes of unknown space.
    std::mt19937_64 rng(seed * 77);
    std::vector<std::array<std::int64_t, 6>> holes;
    for (int h = 0; h < 3; ++h) {
      std::array<std::int64_t, 6> b{};
      for (int a = 0; a < 3; ++a) {
        b[a] = static_cast<std::int64_t>(rng() % static_cast<std::uint64_t>(side - 3));
        b[a + 3] = b[a] + 2 + static_cast<std::int64_t>(rng() % 6);
      }
      holes.push_back(b);
    }
    std::vector<vola::Voxel> known_voxels;
    for (std::uint32_t z = 0; z < side; ++z)
      for (std::uint32_t y = 0; y < side; ++y)
        for (std::uint32_t x = 0; x < side; ++x) {
          bool hole = false;
          for (const auto& b : holes)
            hole = hole || (x >= b[0] && x < b[3] && y >= b[1] && y < b[4] && z >= b[2] && z < b[5]);
          if (!hole || tree.contains(vola::Voxel{x, y, z})) known_voxels.push_back({x, y, z});
        }
    const vola::Tree known = vola::build_from_voxels(known_voxels, 2);
    for (const double radius : {0.0, 0.9}) {
      const auto free = brute_free(tree, radius);
      const auto known_free = brute_known_free(known, free, radius);
      for (int trial = 0; trial < 8; ++trial) {
        std::array<std::int64_t, 3> s{}, g{};
        auto random_free = [&](std::array<std::int64_t, 3>& c) {
          do {
            for (auto& x : c) x = static_cast<std::int64_t>(rng() % static_cast<std::uint64_t>(side));
          } while (!known_free[static_cast<std::size_t>((c[2] * side + c[1]) * side + c[0])]);
        };
        random_free(s);
        random_free(g);
        const double expected = dijkstra(known_free, side, s, g);
        const Point from{double(s[0]) + 0.5, double(s[1]) + 0.5, double(s[2]) + 0.5},
            to{double(g[0]) + 0.5, double(g[1]) + 0.5, double(g[2]) + 0.5};
        PlanOptions options;
        options.radius = radius;
        options.known = &known;
        if (std::isinf(expected)) {
          EXPECT_THROW(plan_path(tree, from, to, options), vola::InvalidArgument);
          ++unreachable;
          continue;
        }
        const auto path = plan_path(tree, from, to, options);
        EXPECT_NEAR(path.cost, expected, 1e-9) << "seed " << seed << " radius " << radius;
        EXPECT_EQ(vola::test::legs_clear(tree, &known, path.points, radius), "") << "seed " << seed;
        longer += expected > dijkstra(free, side, s, g) + 1e-9;
        ++compared;
      }
    }
    // A start in unknown space is refused by name.
    const auto& b = holes[0];
    const Point in_hole{double(b[0]) + 0.5, double(b[1]) + 0.5, double(b[2]) + 0.5};
    if (!tree.contains(vola::Voxel{static_cast<std::uint32_t>(b[0]), static_cast<std::uint32_t>(b[1]),
                                   static_cast<std::uint32_t>(b[2])})) {
      PlanOptions options;
      options.known = &known;
      try {
        plan_path(tree, in_hole, in_hole, options);
        ADD_FAILURE() << "a start in unknown space was accepted";
      } catch (const vola::InvalidArgument& e) {
        EXPECT_NE(std::string(e.what()).find("unknown space"), std::string::npos) << e.what();
      }
    }
  }
  EXPECT_GT(compared, 40);
  EXPECT_GT(longer, 0);  // unknown space did make some paths go round
}

TEST(PathPlanner, CoarseAndHierarchicalPlans) {
  const vola::Tree tree = maze(5, 3);
  const Point from{0.5, 0.5, 0.5}, to{63.5, 63.5, 63.5};
  PlanOptions fine;
  fine.smooth = false;
  const auto optimal = plan_path(tree, from, to, fine);
  PlanOptions hierarchical = fine;
  hierarchical.hierarchical = true;
  const auto h = plan_path(tree, from, to, hierarchical);
  EXPECT_GE(h.cost, optimal.cost - 1e-9);
  EXPECT_EQ(vola::test::legs_clear(tree, nullptr, h.points, 0.0), "");
  // Level 1 of a depth-3 tree: cells of 4 voxels, centres at 2, 6, ...
  PlanOptions coarse = fine;
  coarse.level = 1;
  try {
    const auto c = plan_path(tree, {2, 2, 2}, {62, 62, 62}, coarse);
    EXPECT_EQ(c.points.front(), (Point{2, 2, 2}));
  } catch (const vola::InvalidArgument& e) {
    EXPECT_NE(std::string(e.what()).find("plan:"), std::string::npos);
  }
}

TEST(PathPlanner, ClearErrors) {
  const vola::Voxel wall[] = {{4, 4, 4}};
  const vola::Tree tree = vola::build_from_voxels(wall, 2);
  auto message = [&](const Point& s, const Point& g, double radius) {
    PlanOptions o;
    o.radius = radius;
    try {
      plan_path(tree, s, g, o);
    } catch (const vola::InvalidArgument& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message({-1, 0, 0}, {1, 1, 1}, 0).find("start (-1, 0, 0) is outside the volume"), std::string::npos);
  EXPECT_NE(message({1, 1, 1}, {16, 1, 1}, 0).find("goal (16, 1, 1) is outside"), std::string::npos);
  EXPECT_NE(message({4.5, 4.5, 4.5}, {1, 1, 1}, 0).find("start (4.5, 4.5, 4.5) is inside an obstacle"), std::string::npos);
  EXPECT_NE(message({1, 1, 1}, {5.5, 4.5, 4.5}, 1.5).find("goal (5.5, 4.5, 4.5) is inside an obstacle or closer than the radius"),
            std::string::npos);
  // A closed box around the goal: unreachable.
  std::vector<vola::Voxel> box;
  for (std::uint32_t z = 5; z <= 7; ++z)
    for (std::uint32_t y = 5; y <= 7; ++y)
      for (std::uint32_t x = 5; x <= 7; ++x)
        if (!(x == 6 && y == 6 && z == 6)) box.push_back({x, y, z});
  const vola::Tree closed = vola::build_from_voxels(box, 2);
  EXPECT_THROW(
      {
        try {
          plan_path(closed, {0.5, 0.5, 0.5}, {6.5, 6.5, 6.5});
        } catch (const vola::InvalidArgument& e) {
          EXPECT_NE(
              std::string(e.what()).find("cannot be reached from (0.5, 0.5, 0.5): the goal lies in a closed region "
                                         "of 1 free cells"),
              std::string::npos)
              << e.what();
          throw;
        }
      },
      vola::InvalidArgument);
  // Given the world frame, the errors speak in world coordinates, as the caller gave them.
  const vola::Frame world{vola::Quantization::grid, {1000, 2000, 10}, 0.5};
  PlanOptions in_world;
  in_world.world = &world;
  const auto world_message = [&](const Point& s, const Point& g) {
    try {
      plan_path(tree, s, g, in_world);
    } catch (const vola::InvalidArgument& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(world_message({-2, 0, 0}, {1, 1, 1}).find("start (999, 2000, 10) is outside the volume (1000, 2000, 10) to "
                                                      "(1008, 2008, 18) (world coordinates)"),
            std::string::npos)
      << world_message({-2, 0, 0}, {1, 1, 1});
  EXPECT_NE(world_message({1, 1, 1}, {4.5, 4.5, 4.5}).find("goal (1002.25, 2002.25, 12.25) is inside an obstacle"),
            std::string::npos);
  EXPECT_THROW(plan_path(tree, {1, 1, 1}, {2, 2, 2}, PlanOptions{.level = 2}), vola::InvalidArgument);
  // The search's limit is not unreachability: the message says which it was.
  try {
    plan_path(tree, {0.5, 0.5, 0.5}, {15.5, 15.5, 15.5}, PlanOptions{.max_expansions = 5});
    ADD_FAILURE() << "a search past its limit returned";
  } catch (const vola::InvalidArgument& e) {
    EXPECT_NE(std::string(e.what()).find("within the limit of 5 expanded cells"), std::string::npos) << e.what();
  }
  // A cavity larger than the check before the search (4096 cells): the search gives up at
  // its limit, and the message says the goal is sealed in, not "a larger limit may find one".
  std::vector<vola::Voxel> shell;
  for (std::uint32_t z = 10; z <= 29; ++z)
    for (std::uint32_t y = 10; y <= 29; ++y)
      for (std::uint32_t x = 10; x <= 29; ++x)
        if (x == 10 || x == 29 || y == 10 || y == 29 || z == 10 || z == 29) shell.push_back({x, y, z});
  const vola::Tree sealed = vola::build_from_voxels(shell, 3);  // a cavity of 18^3 = 5832 cells
  try {
    plan_path(sealed, {0.5, 0.5, 0.5}, {20.5, 20.5, 20.5}, PlanOptions{.max_expansions = 20000});
    ADD_FAILURE() << "a path into a sealed cavity";
  } catch (const vola::InvalidArgument& e) {
    EXPECT_NE(std::string(e.what()).find("the goal lies in a closed region of 5832 free cells"), std::string::npos)
        << e.what();
  }
  // A radius the clearance field cannot reach in one word: refused, naming the way out.
  EXPECT_NE(message({1, 1, 1}, {2, 2, 2}, 30).find("coarser level"), std::string::npos);
}

// A diagonal move may not cut the corner between two obstacles: at radius 0 the two
// voxels (1,0,0) and (0,1,0) close the diagonal from (0,0,0) to (1,1,0).
TEST(PathPlanner, NoCornerCutting) {
  const vola::Voxel corner[] = {{1, 0, 0}, {0, 1, 0}};
  const vola::Tree tree = vola::build_from_voxels(corner, 2);
  PlanOptions o;
  o.smooth = false;
  const auto path = plan_path(tree, {0.5, 0.5, 0.5}, {1.5, 1.5, 0.5}, o);
  EXPECT_GT(path.cost, std::sqrt(2.0) + 1e-9);  // not the one diagonal step
  EXPECT_EQ(vola::test::legs_clear(tree, nullptr, path.points, 0.0), "");
}

}  // namespace
