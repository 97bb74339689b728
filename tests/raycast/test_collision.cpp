// Collision queries against brute force over every voxel of random trees.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "raycast_test_scenes.hpp"
#include "vola/builder.hpp"
#include "vola/error.hpp"
#include "vola/raycast/collision.hpp"
#include "vola/raycast/reference_dda.hpp"

namespace {

using vola::Point;
using vola::raycast::Collider;

bool brute_sphere(const vola::Tree& tree, const Point& c, double r) {
  bool any = false;
  tree.for_each_voxel([&](const vola::Voxel& v) {
    const double cell[3] = {double(v.x), double(v.y), double(v.z)};
    double d2 = 0;
    for (int a = 0; a < 3; ++a) {
      const double nearest = std::clamp(c[a], cell[a], cell[a] + 1.0);
      d2 += (c[a] - nearest) * (c[a] - nearest);
    }
    any = any || d2 <= r * r;
  });
  return any;
}

bool brute_box(const vola::Tree& tree, const vola::Box& b) {
  bool any = false;
  tree.for_each_voxel([&](const vola::Voxel& v) {
    const double cell[3] = {double(v.x), double(v.y), double(v.z)};
    bool overlap = true;
    for (int a = 0; a < 3; ++a) overlap = overlap && b.min[a] < cell[a] + 1.0 && b.max[a] > cell[a];
    any = any || overlap;
  });
  return any;
}

TEST(Collision, AgreesWithBruteForceOnRandomTrees) {
  std::size_t positives[3] = {0, 0, 0}, total = 0;
  for (std::uint64_t seed = 100; seed < 112; ++seed) {
    const int depth = 2 + static_cast<int>(seed % 3);
    const vola::Tree tree = raycast_test::random_tree(seed, depth);
    const Collider collider(tree);
    std::mt19937_64 rng(seed);
    const double side = tree.side();
    std::uniform_real_distribution<double> pos(-2.0, side + 2.0), radius(0.0, side / 2.0);
    std::uniform_int_distribution<int> grid(-1, static_cast<int>(side) + 1);
    for (int i = 0; i < 400; ++i, ++total) {
      // Half the queries on integer coordinates, where touching decides.
      const bool exact = i % 2;
      const Point c = exact ? Point{double(grid(rng)), double(grid(rng)), double(grid(rng))}
                            : Point{pos(rng), pos(rng), pos(rng)};
      const double r = exact ? double(rng() % 3) : radius(rng);
      const bool sphere = collider.sphere(c, r);
      ASSERT_EQ(sphere, brute_sphere(tree, c, r)) << "seed " << seed << " sphere " << i;
      vola::Box box{c, c};
      for (int a = 0; a < 3; ++a) box.max[a] += exact ? double(rng() % 3) : radius(rng);
      const bool hit_box = collider.box(box);
      ASSERT_EQ(hit_box, brute_box(tree, box)) << "seed " << seed << " box " << i;
      const Point e{pos(rng), pos(rng), pos(rng)};
      const Point d{e[0] - c[0], e[1] - c[1], e[2] - c[2]};
      const auto segment = collider.segment(c, e);
      ASSERT_EQ(segment, vola::raycast::reference_cast(tree, {c, d, 1.0})) << "seed " << seed << " segment " << i;
      positives[0] += sphere;
      positives[1] += hit_box;
      positives[2] += segment.has_value();
    }
  }
  // Both answers occur often enough for the comparison to mean something.
  for (const std::size_t p : positives) {
    EXPECT_GT(p, total / 50);
    EXPECT_LT(p, total - total / 50);
  }
}

TEST(Collision, TouchingRules) {
  const vola::Voxel v{2, 2, 2};
  const vola::Tree tree = vola::build_from_voxels(std::span(&v, 1), 2);
  const Collider c(tree);
  EXPECT_TRUE(c.sphere({1, 2.5, 2.5}, 1.0));    // touches the x = 2 face
  EXPECT_FALSE(c.sphere({1, 2.5, 2.5}, 0.999));
  EXPECT_TRUE(c.sphere({2.5, 2.5, 2.5}, 0.0));  // a point inside
  EXPECT_FALSE(c.box({{0, 0, 0}, {2, 2, 2}}));  // shares only the corner
  EXPECT_TRUE(c.box({{0, 0, 0}, {2.01, 2.01, 2.01}}));
  EXPECT_TRUE(c.segment({0.5, 2.5, 2.5}, {2.5, 2.5, 2.5}));
  EXPECT_FALSE(c.segment({0.5, 2.5, 2.5}, {1.5, 2.5, 2.5}));
  // A segment of no length is its point: the voxel holding it, at t = 0, or nothing.
  EXPECT_FALSE(c.segment({1, 1, 1}, {1, 1, 1}));
  EXPECT_EQ(c.segment({2.5, 2.9, 2.1}, {2.5, 2.9, 2.1}), (vola::raycast::RayHit{v, 0.0, {0, 0, 0}}));
  EXPECT_FALSE(c.segment({-1, 2.5, 2.5}, {-1, 2.5, 2.5}));
  EXPECT_THROW(c.segment({1e300, 1, 1}, {1e300, 1, 1}), vola::InvalidArgument);
  EXPECT_THROW(c.sphere({1, 1, 1}, -1), vola::InvalidArgument);
  // Squares of 1e308 overflowed to infinity, and infinity <= infinity "hit".
  EXPECT_THROW(c.sphere({1e308, 1e308, 1e308}, 1e308), vola::InvalidArgument);
  EXPECT_FALSE(c.sphere({1e12, 1e12, 1e12}, 1e12));  // the voxel is 1.73e12 away
  EXPECT_TRUE(c.sphere({1e12, 1e12, 1e12}, 1.8e12));
  EXPECT_TRUE(c.sphere({-1e12, 0, 0}, 1e300));
  EXPECT_THROW(c.box({{2, 0, 0}, {1, 1, 1}}), vola::InvalidArgument);
}

}  // namespace
