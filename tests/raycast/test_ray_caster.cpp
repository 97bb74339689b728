// The hierarchical caster against the voxel-by-voxel reference DDA: the same hit voxel,
// entry time and normal, bit for bit, on random trees (depths 3..6), on a real survey and
// on hand-made edge cases whose answers are worked out below.
#include <gtest/gtest.h>

#include "raycast_test_scenes.hpp"
#include "test_support.hpp"
#include "vola/builder.hpp"
#include "vola/error.hpp"
#include "vola/raycast/ray_caster.hpp"
#include "vola/raycast/reference_dda.hpp"

namespace {

using vola::raycast::Ray;
using vola::raycast::RayCaster;
using vola::raycast::RayHit;
using vola::raycast::reference_cast;

std::string describe(const Ray& r) {
  std::ostringstream s;
  s.precision(17);
  s << "origin (" << r.origin[0] << ", " << r.origin[1] << ", " << r.origin[2] << ") direction (" << r.direction[0]
    << ", " << r.direction[1] << ", " << r.direction[2] << ") t_max " << r.t_max;
  return s.str();
}

// Counts the rays that hit, and fails on the first disagreement.
std::size_t expect_agreement(const vola::Tree& tree, const std::vector<Ray>& rays) {
  const RayCaster caster(tree);
  std::vector<std::optional<RayHit>> batch(rays.size());
  caster.cast(rays, batch, 2);
  std::size_t hits = 0;
  for (std::size_t i = 0; i < rays.size(); ++i) {
    const auto expected = reference_cast(tree, rays[i]);
    const auto got = caster.cast(rays[i]);
    if (expected != got || batch[i] != got) {
      ADD_FAILURE() << "ray " << i << ": " << describe(rays[i]) << "\n reference "
                    << (expected ? "hit" : "miss") << ", hierarchical " << (got ? "hit" : "miss")
                    << (expected && got ? " (voxel, t or normal differ)" : "");
      if (expected && got)
        ADD_FAILURE() << "reference (" << expected->voxel.x << "," << expected->voxel.y << "," << expected->voxel.z
                      << ") t " << expected->t << " vs (" << got->voxel.x << "," << got->voxel.y << ","
                      << got->voxel.z << ") t " << got->t;
      return hits;
    }
    hits += expected.has_value();
  }
  return hits;
}

// 100,000 rays over 20 random trees of depths 3..6.
TEST(RayCaster, AgreesWithReferenceOnRandomTrees) {
  std::size_t rays_total = 0, hits = 0;
  for (std::uint64_t seed = 1; seed <= 20; ++seed) {
    const int depth = 3 + static_cast<int>(seed % 4);
    const vola::Tree tree = raycast_test::random_tree(seed, depth);
    std::mt19937_64 rng(seed * 7919);
    const auto rays = raycast_test::mixed_rays(tree, 5000, rng);
    SCOPED_TRACE("seed " + std::to_string(seed) + " depth " + std::to_string(depth));
    hits += expect_agreement(tree, rays);
    rays_total += rays.size();
    if (HasFailure()) return;
  }
  EXPECT_EQ(rays_total, 100000u);
  EXPECT_GT(hits, 10000u);  // the comparison is not between two empty answers
}

TEST(RayCaster, AgreesWithReferenceOnARealSurvey) {
  auto tree = raycast_test::autzen_tree("pdal_autzen-utm.las", 5);
  if (!tree) {
    if (std::getenv("CI")) FAIL() << "shared data missing (CI is set)";
    GTEST_SKIP() << "shared data missing; set VOLA_SHARED";
  }
  std::mt19937_64 rng(42);
  const auto rays = raycast_test::mixed_rays(*tree, 100000, rng);
  EXPECT_GT(expect_agreement(*tree, rays), 5000u);
}

// One voxel, (5, 5, 5), in a 16^3 grid.
vola::Tree single_voxel() {
  const vola::Voxel v{5, 5, 5};
  return vola::build_from_voxels(std::span(&v, 1), 2);
}

std::optional<RayHit> both(const vola::Tree& tree, const Ray& ray) {
  const auto reference = reference_cast(tree, ray);
  EXPECT_EQ(reference, RayCaster(tree).cast(ray)) << describe(ray);
  return reference;
}

TEST(RayCaster, EdgeCasesWithKnownAnswers) {
  const vola::Tree tree = single_voxel();
  // Along +x: enters through the x = 5 face at t = 4.5.
  auto hit = both(tree, {{0.5, 5.5, 5.5}, {1, 0, 0}});
  ASSERT_TRUE(hit);
  EXPECT_EQ(hit->voxel, (vola::Voxel{5, 5, 5}));
  EXPECT_EQ(hit->t, 4.5);
  EXPECT_EQ(hit->normal, (std::array<int, 3>{-1, 0, 0}));
  // Along -z from above the grid: enters the grid at z = 16, the voxel at z = 6.
  hit = both(tree, {{5.5, 5.5, 20.0}, {0, 0, -1}});
  ASSERT_TRUE(hit);
  EXPECT_EQ(hit->t, 14.0);
  EXPECT_EQ(hit->normal, (std::array<int, 3>{0, 0, 1}));
  // Starting inside: t = 0, no normal.
  hit = both(tree, {{5.25, 5.5, 5.75}, {0, -1, 0}});
  ASSERT_TRUE(hit);
  EXPECT_EQ(hit->t, 0.0);
  EXPECT_EQ(hit->normal, (std::array<int, 3>{0, 0, 0}));
  // Diagonal through the corners (3,3,3), (4,4,4), (5,5,5): x is the lowest tied axis.
  hit = both(tree, {{2, 2, 2}, {1, 1, 1}});
  ASSERT_TRUE(hit);
  EXPECT_EQ(hit->t, 3.0);
  EXPECT_EQ(hit->normal, (std::array<int, 3>{-1, 0, 0}));
  // In the plane y = 5 moving along x: the voxel above the plane (y index 5) is hit,
  // the one below is not; in the plane y = 6 nothing is hit.
  EXPECT_TRUE(both(tree, {{0.5, 5.0, 5.5}, {1, 0, 0}}));
  EXPECT_FALSE(both(tree, {{0.5, 6.0, 5.5}, {1, 0, 0}}));
  // Through the edge x = y = 6: (5, 6, 5) then (6, 5, 5); (5, 5, 5) is only touched.
  EXPECT_FALSE(both(tree, {{5.5, 6.5, 5.5}, {1, -1, 0}}));
  // The same edge approached along the other diagonal goes through the voxel.
  EXPECT_TRUE(both(tree, {{6.5, 6.5, 5.5}, {-1, -1, 0}}));
  // Stopping short: the face is at t = 4.5.
  EXPECT_FALSE(both(tree, {{0.5, 5.5, 5.5}, {1, 0, 0}, 4.4}));
  EXPECT_TRUE(both(tree, {{0.5, 5.5, 5.5}, {1, 0, 0}, 4.5}));
  // Outside, moving away, or grazing the cube's edge only.
  EXPECT_FALSE(both(tree, {{-3, 5.5, 5.5}, {-1, 0, 0}}));
  EXPECT_FALSE(both(tree, {{-1, 17, 5.5}, {1, -1, 0}}));
  // From far outside, entering through a corner of the grid.
  hit = both(tree, {{-10, -10, -10}, {1, 1, 1}});
  ASSERT_TRUE(hit);
  EXPECT_EQ(hit->t, 15.0);
}

TEST(RayCaster, RefusesBadRays) {
  const vola::Tree tree = single_voxel();
  const RayCaster caster(tree);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(caster.cast(Ray{{0, 0, 0}, {0, 0, 0}}), vola::InvalidArgument);
  EXPECT_THROW(caster.cast(Ray{{nan, 0, 0}, {1, 0, 0}}), vola::InvalidArgument);
  EXPECT_THROW(caster.cast(Ray{{0, 0, 0}, {1, nan, 0}}), vola::InvalidArgument);
  EXPECT_THROW(caster.cast(Ray{{1e13, 0, 0}, {1, 0, 0}}), vola::InvalidArgument);
  EXPECT_THROW(caster.cast(Ray{{0, 0, 0}, {1, 0, 0}, -1.0}), vola::InvalidArgument);
  EXPECT_THROW(reference_cast(tree, Ray{{0, 0, 0}, {0, 0, 0}}), vola::InvalidArgument);
  std::vector<Ray> rays(3);
  std::vector<std::optional<RayHit>> hits(2);
  EXPECT_THROW(caster.cast(rays, hits), vola::InvalidArgument);
}

TEST(RayCaster, EmptyTreeHasNoHits) {
  const vola::Tree tree;
  EXPECT_FALSE(RayCaster(tree).cast(Ray{{0.5, 0.5, 0.5}, {1, 0, 0}}));
  EXPECT_FALSE(reference_cast(tree, Ray{{0.5, 0.5, 0.5}, {1, 0, 0}}));
}

}  // namespace
