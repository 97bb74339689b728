// ClearanceField against its slow twins: Collider::sphere at every cell centre, and a
// brute force over the voxels near each cell (with known space: unknown and off-grid
// voxels are obstacles too), on random scenes, for radii on and off the half-cell steps.
#include <gtest/gtest.h>

#include <random>

#include "vola/builder.hpp"
#include "vola/error.hpp"
#include "vola/raycast/clearance_field.hpp"
#include "vola/raycast/collision.hpp"
#include "plan_checks.hpp"

namespace {

using vola::raycast::ClearanceField;

// Clusters of voxels (so that bricks mix blocked and free cells) and scattered ones.
vola::Tree scene(std::uint64_t seed, int depth, std::size_t count) {
  std::mt19937_64 rng(seed);
  const std::uint32_t side = vola::side_of(depth);
  std::vector<vola::Voxel> voxels;
  for (std::size_t i = 0; i < count; ++i) {
    const vola::Voxel c{static_cast<std::uint32_t>(rng() % side), static_cast<std::uint32_t>(rng() % side),
                        static_cast<std::uint32_t>(rng() % side)};
    voxels.push_back(c);
    if (i % 4 == 0)  // a small slab around it
      for (std::uint32_t d = 1; d < 6; ++d)
        if (c.x + d < side) voxels.push_back({c.x + d, c.y, c.z});
  }
  return vola::build_from_voxels(voxels, depth);
}

TEST(ClearanceField, EqualsASphereQueryPerCell) {
  for (std::uint64_t seed = 1; seed <= 3; ++seed) {
    const vola::Tree tree = scene(seed, 3, 200);
    const vola::raycast::Collider collider(tree);
    for (const double radius : {0.0, 0.3, 0.5, 0.9, 1.5, 2.9999999999999996, 3.0, 4.2}) {
      ClearanceField field(tree, radius);
      std::uint64_t blocked = 0;
      for (std::int64_t z = 0; z < 64; ++z)
        for (std::int64_t y = 0; y < 64; ++y)
          for (std::int64_t x = 0; x < 64; ++x) {
            const bool expected = !collider.sphere({double(x) + 0.5, double(y) + 0.5, double(z) + 0.5}, radius);
            ASSERT_EQ(field.free(x, y, z), expected) << "cell " << x << " " << y << " " << z << " radius " << radius;
            blocked += !expected;
          }
      EXPECT_GT(blocked, tree.voxel_count() - 1);  // the scene did block cells
      EXPECT_FALSE(field.free(-1, 0, 0));
      EXPECT_FALSE(field.free(0, 64, 0));
    }
  }
}

TEST(ClearanceField, UnknownSpaceAndTheGridEdgeAreObstaclesWithKnown) {
  for (std::uint64_t seed = 1; seed <= 2; ++seed) {
    const vola::Tree tree = scene(seed, 3, 120);
    // Known: every voxel but those in a few random boxes, obstacles always known.
    std::mt19937_64 rng(seed * 13);
    std::vector<std::array<std::uint32_t, 6>> holes;
    for (int h = 0; h < 4; ++h) {
      std::array<std::uint32_t, 6> b{};
      for (int a = 0; a < 3; ++a) {
        b[a] = static_cast<std::uint32_t>(rng() % 56);
        b[a + 3] = b[a] + 2 + static_cast<std::uint32_t>(rng() % 8);
      }
      holes.push_back(b);
    }
    std::vector<vola::Voxel> known_voxels;
    for (std::uint32_t z = 0; z < 64; ++z)
      for (std::uint32_t y = 0; y < 64; ++y)
        for (std::uint32_t x = 0; x < 64; ++x) {
          bool hole = false;
          for (const auto& b : holes) hole = hole || (x >= b[0] && x < b[3] && y >= b[1] && y < b[4] && z >= b[2] && z < b[5]);
          if (!hole || tree.contains(vola::Voxel{x, y, z})) known_voxels.push_back({x, y, z});
        }
    const vola::Tree known = vola::build_from_voxels(known_voxels, 3);
    for (const double radius : {0.0, 0.9, 2.5}) {
      ClearanceField field(tree, radius, &known);
      std::uint64_t free_cells = 0;
      for (std::int64_t z = 0; z < 64; ++z)
        for (std::int64_t y = 0; y < 64; ++y)
          for (std::int64_t x = 0; x < 64; ++x) {
            const double d2 = vola::test::nearest_obstacle2(tree, &known, {double(x) + 0.5, double(y) + 0.5, double(z) + 0.5}, radius + 1.0);
            ASSERT_EQ(field.free(x, y, z), d2 > radius * radius) << x << " " << y << " " << z << " radius " << radius;
            free_cells += d2 > radius * radius;
          }
      EXPECT_GT(free_cells, 1000u);
    }
  }
}

// A sloping sampled ground (a sheet with empty columns) under a few boxes: with
// solid_ground the cells below the ground are blocked too. The brute force: a column's
// ground is the lowest voxel of the columns within 2 on each axis.
TEST(ClearanceField, SolidGroundBlocksTheSpaceUnderASampledSheet) {
  std::mt19937_64 rng(5);
  std::vector<vola::Voxel> voxels;
  for (std::uint32_t y = 0; y < 50; ++y)
    for (std::uint32_t x = 0; x < 60; ++x)
      if (rng() % 3 != 0) voxels.push_back({x, y, 8 + x / 10 + static_cast<std::uint32_t>(rng() % 2)});
  for (std::uint32_t z = 20; z < 26; ++z)  // a roof-like slab over columns that keep their ground
    for (std::uint32_t x = 30; x < 40; ++x) voxels.push_back({x, 20, z});
  const vola::Tree tree = vola::build_from_voxels(voxels, 3);
  std::vector<std::int64_t> lowest(64 * 64, 1 << 30), ground(64 * 64, 1 << 30);
  for (const auto& v : voxels) lowest[v.y * 64 + v.x] = std::min<std::int64_t>(lowest[v.y * 64 + v.x], v.z);
  for (std::int64_t y = 0; y < 64; ++y)
    for (std::int64_t x = 0; x < 64; ++x)
      for (std::int64_t dy = -2; dy <= 2; ++dy)
        for (std::int64_t dx = -2; dx <= 2; ++dx)
          if (x + dx >= 0 && y + dy >= 0 && x + dx < 64 && y + dy < 64)
            ground[y * 64 + x] = std::min(ground[y * 64 + x], lowest[(y + dy) * 64 + x + dx]);
  const auto obstacle = [&](std::int64_t x, std::int64_t y, std::int64_t z) {
    const bool column = x >= 0 && y >= 0 && x < 64 && y < 64;
    if (column && ground[y * 64 + x] < (1 << 30) && z < ground[y * 64 + x]) return true;  // under the ground
    if (!column || z < 0 || z >= 64) return false;
    return tree.contains(vola::Voxel{static_cast<std::uint32_t>(x), static_cast<std::uint32_t>(y), static_cast<std::uint32_t>(z)});
  };
  for (const double radius : {0.0, 1.5, 3.0}) {
    ClearanceField field(tree, radius, nullptr, true);
    ClearanceField open_below(tree, radius);
    std::uint64_t differ = 0;
    const int reach = static_cast<int>(radius + 0.5);
    for (std::int64_t z = 0; z < 40; ++z)
      for (std::int64_t y = 0; y < 64; ++y)
        for (std::int64_t x = 0; x < 64; ++x) {
          bool free = true;
          for (int dz = -reach; dz <= reach && free; ++dz)
            for (int dy = -reach; dy <= reach && free; ++dy)
              for (int dx = -reach; dx <= reach && free; ++dx) {
                const auto g = [](int d) { return d ? (std::abs(d) - 0.5) * (std::abs(d) - 0.5) : 0.0; };
                if (g(dx) + g(dy) + g(dz) <= radius * radius && obstacle(x + dx, y + dy, z + dz)) free = false;
              }
          ASSERT_EQ(field.free(x, y, z), free) << x << " " << y << " " << z << " radius " << radius;
          differ += free != open_below.free(x, y, z);
        }
    EXPECT_GT(differ, 10000u);  // the space under the sheet was free without it
  }
}

TEST(ClearanceField, WholeBricksAndLimits) {
  const vola::Voxel one[] = {{20, 20, 20}};
  const vola::Tree tree = vola::build_from_voxels(one, 3);
  ClearanceField field(tree, 1.0);
  EXPECT_FALSE(field.brick_all_free(1, 1, 1));  // holds the voxel
  EXPECT_TRUE(field.brick_all_free(3, 3, 3));   // far from it: no computation
  EXPECT_TRUE(field.brick_all_free(0, 1, 1));   // within reach of a brick with a voxel: computed
  EXPECT_EQ(field.bricks_computed(), 2u);
  // A grid smaller than a brick: the cells past its edge are never free.
  const vola::Tree small = vola::build_from_voxels(std::span<const vola::Voxel>{}, 1);
  ClearanceField tiny(small, 0.0);
  EXPECT_TRUE(tiny.free(3, 3, 3));
  EXPECT_FALSE(tiny.free(4, 0, 0));
  EXPECT_FALSE(tiny.brick_all_free(0, 0, 0));
  EXPECT_THROW(ClearanceField(tree, 24.6), vola::InvalidArgument);
  EXPECT_NO_THROW(ClearanceField(tree, 24.4));
  EXPECT_THROW(ClearanceField(tree, -1.0), vola::InvalidArgument);
}

}  // namespace
