// Obstacle avoidance: flights that must never bring the agent's sphere into an occupied
// voxel, checked against an exact segment-to-voxel distance over every voxel, on a
// hand-made wall with a hole and on the converted Autzen survey.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "raycast_test_scenes.hpp"
#include "vola/builder.hpp"
#include "vola/error.hpp"
#include "vola/raycast/avoidance.hpp"

namespace {

using vola::Point;
using vola::raycast::AvoidanceOptions;
using vola::raycast::Collider;
using vola::raycast::ObstacleAvoider;

double point_box_distance2(const Point& p, const vola::Voxel& v) {
  const double lo[3] = {double(v.x), double(v.y), double(v.z)};
  double d2 = 0.0;
  for (int a = 0; a < 3; ++a) {
    const double gap = std::max({lo[a] - p[a], 0.0, p[a] - (lo[a] + 1.0)});
    d2 += gap * gap;
  }
  return d2;
}

// The distance from segment a-b to voxel v's cube: the squared distance from a point
// moving along the segment to a convex set is convex, so a ternary search finds it.
double segment_box_distance(const Point& a, const Point& b, const vola::Voxel& v) {
  auto at = [&](double s) {
    return point_box_distance2(Point{a[0] + s * (b[0] - a[0]), a[1] + s * (b[1] - a[1]), a[2] + s * (b[2] - a[2])}, v);
  };
  double lo = 0.0, hi = 1.0;
  for (int i = 0; i < 100; ++i) {
    const double m1 = lo + (hi - lo) / 3, m2 = hi - (hi - lo) / 3;
    if (at(m1) < at(m2)) hi = m2; else lo = m1;
  }
  return std::sqrt(std::min({at(0.0), at(1.0), at(0.5 * (lo + hi))}));
}

// The smallest distance between the flight's path and any occupied voxel, by brute force.
double closest_approach(const std::vector<vola::Voxel>& voxels, const std::vector<Point>& path, double within) {
  double closest = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i + 1 < path.size(); ++i) {
    const Point& a = path[i];
    const Point& b = path[i + 1];
    for (const vola::Voxel& v : voxels) {
      const double lo[3] = {double(v.x), double(v.y), double(v.z)};
      bool near = true;  // cheap box test first: the segment's box grown by `within`
      for (int k = 0; k < 3; ++k)
        near = near && lo[k] + 1.0 >= std::min(a[k], b[k]) - within && lo[k] <= std::max(a[k], b[k]) + within;
      if (near) closest = std::min(closest, segment_box_distance(a, b, v));
    }
  }
  return closest;
}

std::vector<vola::Voxel> all_voxels(const vola::Tree& tree) {
  std::vector<vola::Voxel> voxels;
  tree.for_each_voxel([&](const vola::Voxel& v) { voxels.push_back(v); });
  return voxels;
}

double distance(const Point& a, const Point& b) { return std::hypot(a[0] - b[0], a[1] - b[1], a[2] - b[2]); }

TEST(Avoidance, AroundAWallThroughItsHole) {
  // A wall x = 30 filling the grid's y, z in [0, 64) except an 8x8 hole at y, z in
  // [24, 32), off the straight line from start to goal but within the fan's look-ahead.
  std::vector<vola::Voxel> wall;
  for (std::uint32_t y = 0; y < 64; ++y)
    for (std::uint32_t z = 0; z < 64; ++z)
      if (!(y >= 24 && y < 32 && z >= 24 && z < 32)) wall.push_back({30, y, z});
  const vola::Tree tree = vola::build_from_voxels(wall, 3);
  const Collider collider(tree);
  AvoidanceOptions options;
  options.radius = 1.5;
  options.speed = 0.75;
  const ObstacleAvoider avoider(collider, options);
  const Point start{10, 20, 20}, goal{50, 20, 20};
  ASSERT_TRUE(collider.segment(start, goal).has_value()) << "the straight line must be blocked";
  const auto flight = vola::raycast::fly(avoider, start, goal, 2000);
  EXPECT_TRUE(flight.reached) << "ended at " << flight.positions.back()[0] << " " << flight.positions.back()[1] << " "
                              << flight.positions.back()[2] << " after " << flight.positions.size() << " steps";
  EXPECT_GT(closest_approach(wall, flight.positions, options.radius + 1.0), options.radius);
  // Every step is at most `speed` long, and the flight ends on the goal itself.
  for (std::size_t i = 1; i < flight.positions.size(); ++i)
    EXPECT_LE(distance(flight.positions[i - 1], flight.positions[i]), options.speed + 1e-12);
  EXPECT_EQ(flight.positions.back(), goal);
}

// "Near the goal" is not "at the goal": a tolerance wider than the gap to the goal must not
// skip the last leg or its collision check (vola plan --avoid --speed 20 once reported the
// goal reached from 14 voxels away, across an occupied voxel).
TEST(Avoidance, TheLastLegOntoTheGoalIsCheckedLikeEveryStep) {
  const std::vector<vola::Voxel> voxels{{0, 0, 0}, {1, 1, 1}, {5, 5, 5}, {15, 15, 15}};
  const vola::Tree tree = vola::build_from_voxels(voxels, 2);
  const Collider collider(tree);
  AvoidanceOptions options;
  options.radius = 0.5;
  options.speed = 20.0;
  const ObstacleAvoider avoider(collider, options);
  const Point start{2.5, 2.5, 2.5}, goal{10.5, 10.5, 10.5};
  const auto blocked = vola::raycast::fly(avoider, start, goal, 100, 20.0);
  EXPECT_FALSE(blocked.reached);  // within the tolerance from the start, but (5, 5, 5) lies between
  EXPECT_EQ(blocked.positions.size(), 1u);
  const auto flown = vola::raycast::fly(avoider, start, goal, 100);
  EXPECT_TRUE(flown.reached);
  EXPECT_EQ(flown.positions.back(), goal);
  EXPECT_GT(closest_approach(voxels, flown.positions, options.radius + 1.0), options.radius);
}

TEST(Avoidance, HoldsWhenBoxedIn) {
  // A closed 10^3 box shell around the agent: no way out, and no step into it either.
  std::vector<vola::Voxel> shell;
  for (std::uint32_t x = 10; x <= 20; ++x)
    for (std::uint32_t y = 10; y <= 20; ++y)
      for (std::uint32_t z = 10; z <= 20; ++z)
        if (x == 10 || x == 20 || y == 10 || y == 20 || z == 10 || z == 20) shell.push_back({x, y, z});
  const vola::Tree tree = vola::build_from_voxels(shell, 3);
  const Collider collider(tree);
  AvoidanceOptions options;
  options.radius = 1.0;
  const ObstacleAvoider avoider(collider, options);
  const auto flight = vola::raycast::fly(avoider, Point{15.5, 15.5, 15.5}, Point{40, 40, 40}, 500);
  EXPECT_FALSE(flight.reached);
  EXPECT_GT(closest_approach(shell, flight.positions, options.radius + 1.0), options.radius);
  for (const Point& p : flight.positions)
    for (int a = 0; a < 3; ++a) EXPECT_TRUE(p[a] > 11.0 && p[a] < 20.0);
}

TEST(Avoidance, ClearErrors) {
  const std::vector<vola::Voxel> one{{5, 5, 5}};
  const vola::Tree tree = vola::build_from_voxels(one, 2);
  const Collider collider(tree);
  AvoidanceOptions bad;
  bad.speed = 0.0;
  EXPECT_THROW(ObstacleAvoider(collider, bad), vola::InvalidArgument);
  bad = {};
  bad.rings = 1;
  EXPECT_THROW(ObstacleAvoider(collider, bad), vola::InvalidArgument);
  const ObstacleAvoider avoider(collider, {});
  EXPECT_THROW(avoider.step(Point{5.5, 5.5, 5.5}, Point{0, 0, 0}, Point{1, 1, 1}), vola::InvalidArgument);
  EXPECT_THROW(avoider.step(Point{1, 1, NAN}, Point{0, 0, 0}, Point{1, 1, 1}), vola::InvalidArgument);
}

// A scripted flythrough of the Autzen survey (ground, trees and buildings; voxels of
// about a foot): low passes across the survey at heights inside the trees and
// buildings, each from one end to the other. Every pass must keep the agent's sphere
// clear of every voxel; the passes whose straight line is blocked must still arrive.
TEST(Avoidance, FlythroughOfARealSurveyNeverCollides) {
  const auto tree = raycast_test::autzen_tree("pdal_autzen_trim.las", 5);
  if (!tree) {
    if (std::getenv("CI")) FAIL() << "shared data missing (CI is set)";
    GTEST_SKIP() << "shared data missing; set VOLA_SHARED";
  }
  const std::vector<vola::Voxel> voxels = all_voxels(*tree);
  std::uint32_t lo[3] = {UINT32_MAX, UINT32_MAX, UINT32_MAX}, hi[3] = {0, 0, 0};
  for (const vola::Voxel& v : voxels) {
    const std::uint32_t c[3] = {v.x, v.y, v.z};
    for (int a = 0; a < 3; ++a) lo[a] = std::min(lo[a], c[a]), hi[a] = std::max(hi[a], c[a]);
  }
  const Collider collider(*tree);
  AvoidanceOptions options;
  options.radius = 2.0;
  options.speed = 1.5;
  const ObstacleAvoider avoider(collider, options);

  int blocked_and_arrived = 0;
  for (int pass = 0; pass < 4; ++pass) {
    // Across x at four y positions, at a height where the ends are free: from just
    // above the lowest voxels upwards.
    const double y = lo[1] + (hi[1] - lo[1]) * (0.2 + 0.2 * pass);
    Point start{lo[0] + 3.0, y, 0.0}, goal{hi[0] - 3.0, y, 0.0};
    double z = lo[2] + 0.35 * (hi[2] - lo[2]);
    while (z < hi[2] && (collider.sphere(Point{start[0], y, z}, options.radius + 1) ||
                         collider.sphere(Point{goal[0], y, z}, options.radius + 1)))
      z += 1.0;
    start[2] = goal[2] = z;
    const bool blocked = collider.segment(start, goal).has_value();
    const auto flight = vola::raycast::fly(avoider, start, goal, 6000);
    const double approach = closest_approach(voxels, flight.positions, options.radius + 1.0);
    EXPECT_GT(approach, options.radius) << "pass " << pass << " collided";
    if (blocked && flight.reached) ++blocked_and_arrived;
    std::printf("pass %d at height %.0f: straight line %s, %zu steps, %s, closest approach %.2f voxels\n", pass, z,
                blocked ? "blocked" : "free", flight.positions.size() - 1, flight.reached ? "arrived" : "did not arrive",
                approach);
  }
  EXPECT_GE(blocked_and_arrived, 2) << "the flythrough must weave past obstacles on at least two passes";
}

}  // namespace
