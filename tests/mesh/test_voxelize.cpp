// The voxelizer against the brute force (the same exact test on every voxel of small
// grids) and against dense sampling of points on each triangle.
#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <string>

#include <gtest/gtest.h>

#include "mesh_test_support.hpp"
#include "vola/mesh/voxelize.hpp"

namespace {

using vola::Box;
using vola::Point;
using vola::Quantizer;
using vola::mesh::Triangle;
using vola_mesh_test::XyzSet;

struct Scenario {
  std::string name;
  Quantizer quantizer;
  Box region;  // where the random triangles go (grown by 20%)
  int triangles;
  // Voxels larger than the rounding of the coordinates: points computed on a triangle
  // then lie on it to well within a voxel (the sampling check needs that).
  bool resolvable = true;
};

std::vector<Scenario> scenarios() {
  return {
      {"toolkit depth 1", Quantizer::toolkit({{0, 0, 0}, {1, 1, 1}}, 1), {{0, 0, 0}, {1, 1, 1}}, 440},
      {"toolkit depth 2, flat bbox", Quantizer::toolkit({{-3, 2, 10}, {5, 4, 11}}, 2), {{-3, 2, 10}, {5, 4, 11}}, 330},
      {"toolkit depth 3, offset", Quantizer::toolkit({{1000.5, 2000.25, -7}, {1010.5, 2003, -1}}, 3),
       {{1000.5, 2000.25, -7}, {1010.5, 2003, -1}}, 44},
      {"grid depth 2, part outside", Quantizer::grid({-1, -1, -1}, 0.13, 2), {{-1.5, -1.5, -1.5}, {1.5, 1.5, 1.5}}, 330},
      {"grid depth 3, UTM-sized coordinates", Quantizer::grid({500000, 4000000, 100}, 0.5, 3),
       {{500000, 4000000, 100}, {500032, 4000032, 132}}, 44},
      {"toolkit, zero-extent bbox", Quantizer::toolkit({{2, 2, 2}, {2, 2, 2}}, 1), {{1, 1, 1}, {3, 3, 3}}, 110},
      {"toolkit, an axis below the coordinates' resolution", Quantizer::toolkit({{1e20, 0, 0}, {1e20, 1, 1}}, 2),
       {{1e20, 0, 0}, {1e20, 1, 1}}, 110},
      {"grid, voxels below the coordinates' resolution", Quantizer::grid({1e12, 0, 0}, 1e-6, 2),
       {{1e12, 0, 0}, {1e12 + 1e-5, 1e-5, 1e-5}}, 110, false},
      // Products of coordinates this small underflow unless the test rescales (a fuzz finding).
      {"toolkit, a bbox of 1e-300", Quantizer::toolkit({{0, 0, 0}, {1e-300, 1e-300, 2e-300}}, 2),
       {{0, 0, 0}, {1e-300, 1e-300, 2e-300}}, 110},
      {"toolkit, a bbox of 1e250", Quantizer::toolkit({{-1e250, 0, 0}, {1e250, 1e250, 1e250}}, 2),
       {{-1e250, 0, 0}, {1e250, 1e250, 1e250}}, 110},
      // Faces once overflowed there ((k + 1/2) * scale before dividing; a fuzz finding).
      {"toolkit, a bbox of 1e308", Quantizer::toolkit({{0, 0, -1e308}, {1, 1, 0}}, 2), {{0, 0, -1}, {1, 1, 0}}, 110},
  };
}

TEST(Voxelize, EveryTriangleMatchesTheBruteForce) {
  std::mt19937_64 rng(11);
  for (const Scenario& s : scenarios()) {
    const auto triangles = vola_mesh_test::random_triangles(rng, s.region, s.quantizer, s.triangles);
    XyzSet all_expected;
    for (std::size_t i = 0; i < triangles.size(); ++i) {
      const std::span<const Triangle> one(&triangles[i], 1);
      const XyzSet expected = vola_mesh_test::brute_force_voxels(one, s.quantizer);
      const XyzSet got = vola_mesh_test::key_set(vola::mesh::surface_keys(one, s.quantizer));
      EXPECT_EQ(got, expected) << s.name << ", triangle " << i << " (kind " << i % 11 << ")";
      all_expected.insert(expected.begin(), expected.end());
    }
    vola::mesh::VoxelizeReport report;
    const auto keys = vola::mesh::surface_keys(triangles, s.quantizer, &report);
    EXPECT_TRUE(std::is_sorted(keys.begin(), keys.end()) && std::adjacent_find(keys.begin(), keys.end()) == keys.end());
    EXPECT_EQ(vola_mesh_test::key_set(keys), all_expected) << s.name;
    EXPECT_EQ(report.triangles, triangles.size());
    EXPECT_EQ(report.surface_voxels, keys.size());
    const auto unusable = std::count_if(triangles.begin(), triangles.end(), [](const Triangle& t) {
      return !vola::mesh::TriangleBoxTest(t).usable();
    });
    EXPECT_EQ(report.skipped, static_cast<std::uint64_t>(unusable)) << s.name;
  }
}

// A point on a triangle lies in the voxel to_voxel gives it, up to rounding at a face:
// then the voxel across that face must be set.
bool sampled_point_covered(const Point& p, const Quantizer& q, const XyzSet& voxels) {
  vola::Voxel v;
  if (!q.to_voxel(p, v)) return true;  // outside a grid-mode grid
  if (voxels.count(vola_test::to_xyz(v))) return true;
  const Box cell = q.cell_box(v);
  const std::uint32_t side = vola::side_of(q.depth());
  for (int a = 0; a < 3; ++a) {
    const double tolerance = 1e-9 * (std::abs(p[a]) + q.frame().voxel_size);
    vola_test::Xyz n = vola_test::to_xyz(v);
    if (std::abs(p[a] - cell.min[a]) < tolerance && n[a] > 0) {
      --n[a];
      if (voxels.count(n)) return true;
      ++n[a];
    }
    if (std::abs(p[a] - cell.max[a]) < tolerance && n[a] + 1 < side) {
      ++n[a];
      if (voxels.count(n)) return true;
    }
  }
  return false;
}

TEST(Voxelize, EverySampledPointOfATriangleIsInASetVoxel) {
  std::mt19937_64 rng(12);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (const Scenario& s : scenarios()) {
    if (!s.resolvable) continue;
    const auto triangles = vola_mesh_test::random_triangles(rng, s.region, s.quantizer, s.triangles);
    for (std::size_t i = 0; i < triangles.size(); ++i) {
      const Triangle& t = triangles[i];
      if (!vola::mesh::TriangleBoxTest(t).usable()) continue;  // skipped by design
      const XyzSet voxels = vola_mesh_test::key_set(vola::mesh::surface_keys({&t, 1}, s.quantizer));
      const auto check = [&](double u, double w) {
        Point p;
        for (int a = 0; a < 3; ++a) p[a] = t[0][a] + u * (t[1][a] - t[0][a]) + w * (t[2][a] - t[0][a]);
        EXPECT_TRUE(sampled_point_covered(p, s.quantizer, voxels))
            << s.name << ", triangle " << i << " at (" << p[0] << ", " << p[1] << ", " << p[2] << ")";
      };
      constexpr int n = 60;
      for (int a = 0; a <= n; ++a)
        for (int b = 0; a + b <= n; ++b) check(static_cast<double>(a) / n, static_cast<double>(b) / n);
      for (int k = 0; k < 2000; ++k) {
        double u = unit(rng), w = unit(rng);
        if (u + w > 1) u = 1 - u, w = 1 - w;
        check(u, w);
      }
    }
  }
}

// Big triangles at depth 4 (256^3) take the slab-by-slab path with long rows, where the
// cells inside a row's span are taken without the exact test: triangles on cell faces
// (a z face, an x face, an edge along x on a y face) check that only its ends are.
TEST(Voxelize, BigTrianglesMatchTheBruteForce) {
  const Quantizer q = Quantizer::toolkit({{0, 0, 0}, {10, 10, 10}}, 4);
  const double face = q.cell_box({0, 0, 100}).max[2];
  const double x_face = q.cell_box({77, 0, 0}).min[0], y_face = q.cell_box({0, 140, 0}).min[1];
  const std::vector<Triangle> triangles = {
      {{{-1, 0.3, 0.2}, {11, 4, 9.7}, {3, 10.5, 5.1}}},
      {{{0.1, 0.1, face}, {9.9, 0.2, face}, {4, 9.8, face}}},
      {{{x_face, 0.2, 0.3}, {x_face, 9.6, 1.1}, {x_face, 4.4, 9.9}}},
      {{{0.7, y_face, 2.2}, {9.3, y_face, 2.2}, {5.1, 9.9, 8.4}}},
  };
  for (const Triangle& t : triangles)
    EXPECT_EQ(vola_mesh_test::key_set(vola::mesh::surface_keys({&t, 1}, q)),
              vola_mesh_test::brute_force_voxels({&t, 1}, q));
}

// A fuzz finding of the row fast path: this triangle lies in the plane y = z / 7 up to
// rounding and so runs along the corner edges of many rows (y = 2/21, z = 2/3, ...). The
// triangle clipped to such a row without margin is a sliver that rounding alone made;
// the cells of those rows must go through the exact test, which finds no overlap.
TEST(Voxelize, ATriangleGrazingTheEdgesOfRowsMatchesTheBruteForce) {
  const Quantizer q = Quantizer::toolkit({{0, 0, 0}, {4, 4, 4}}, 3);
  const Triangle t{{{0.5, 0.5, 3.5}, {3.5, 0.5, 3.5}, {3.5, 6.9844665281088063e-251, 6.983507489299645e-251}}};
  EXPECT_EQ(vola_mesh_test::key_set(vola::mesh::surface_keys({&t, 1}, q)), vola_mesh_test::brute_force_voxels({&t, 1}, q));
}

TEST(Voxelize, UnusableTrianglesAreSkipped) {
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  const Quantizer q = Quantizer::toolkit({{0, 0, 0}, {1, 1, 1}}, 2);
  const Triangle good{{{0.1, 0.1, 0.1}, {0.9, 0.2, 0.3}, {0.4, 0.8, 0.7}}};
  const std::vector<Triangle> triangles = {
      {{{nan, 0, 0}, {1, 1, 1}, {0, 1, 0}}}, good, {{{0, 0, 0}, {inf, 1, 1}, {0, 1, 0}}},
      {{{0, 0, 0}, {1, 1, 1}, {0, -inf, 0}}}, {{{0, 0, 1e301}, {1, 1, 1}, {0, 1, 0}}}, {{{nan, nan, nan}, {nan, nan, nan}, {nan, nan, nan}}},
  };
  vola::mesh::VoxelizeReport report;
  const auto keys = vola::mesh::surface_keys(triangles, q, &report);
  EXPECT_EQ(report.skipped, 5u);
  EXPECT_EQ(vola_mesh_test::key_set(keys), vola_mesh_test::brute_force_voxels({&good, 1}, q));
  // Bounds come from the usable triangles only.
  const Box bounds = vola::mesh::triangle_bounds(triangles);
  EXPECT_EQ(bounds.min, (Point{0.1, 0.1, 0.1}));
  EXPECT_EQ(bounds.max, (Point{0.9, 0.8, 0.7}));
  EXPECT_EQ(vola::mesh::triangle_bounds({}), Box{});
  // Nothing usable at all: an empty tree, also when solid.
  const std::vector<Triangle> bad(triangles.begin(), triangles.begin() + 1);
  vola::mesh::VoxelizeOptions solid;
  solid.solid = true;
  EXPECT_TRUE(vola::mesh::voxelize(bad, q, solid).empty());
}

// A NaN bbox minimum gives an axis of NaN faces: nothing touches them (a fuzz finding:
// the per-triangle face cache once disagreed with cell_box there).
TEST(Voxelize, NaNFrameAxisSetsNothing) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const Quantizer q = Quantizer::toolkit({{nan, 0, 0}, {1, 1, 1}}, 2);
  std::mt19937_64 rng(14);
  const auto triangles = vola_mesh_test::random_triangles(rng, {{0, 0, 0}, {1, 1, 1}}, q, 44);
  const auto keys = vola::mesh::surface_keys(triangles, q);
  EXPECT_EQ(vola_mesh_test::key_set(keys), vola_mesh_test::brute_force_voxels(triangles, q));
}

TEST(Voxelize, GridModeCountsTrianglesOutsideTheGrid) {
  const Quantizer q = Quantizer::grid({0, 0, 0}, 1.0, 1);  // [0, 4)^3
  const std::vector<Triangle> triangles = {
      {{{10, 10, 10}, {11, 10, 10}, {10, 11, 10}}},
      {{{-3, 1, 1}, {-2, 1, 1}, {-3, 2, 1}}},
      {{{3.5, 3.5, 3.5}, {5, 3.5, 3.5}, {3.5, 5, 3.5}}},  // partly inside
  };
  vola::mesh::VoxelizeReport report;
  const auto keys = vola::mesh::surface_keys(triangles, q, &report);
  EXPECT_EQ(report.outside, 2u);
  EXPECT_EQ(vola_mesh_test::key_set(keys), (XyzSet{{3, 3, 3}}));
}

TEST(Voxelize, TreeCarriesTheKeysAndTheFrame) {
  std::mt19937_64 rng(13);
  const Quantizer q = Quantizer::grid({-1, -1, -1}, 0.25, 2);
  const auto triangles = vola_mesh_test::random_triangles(rng, {{-1, -1, -1}, {3, 3, 3}}, q, 50);
  const vola::Tree tree = vola::mesh::voxelize(triangles, q);
  EXPECT_EQ(tree.keys(), vola::mesh::surface_keys(triangles, q));
  EXPECT_EQ(tree.depth(), 2);
  ASSERT_TRUE(tree.stored_frame().has_value());
  EXPECT_EQ(*tree.stored_frame(), q.frame());
}

}  // namespace
