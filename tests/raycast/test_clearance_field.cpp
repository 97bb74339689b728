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
