// Quantizer::cell_box and Quantizer::voxel_range, which the voxelizer stands on:
// checked against to_voxel and against every voxel of small grids.
#include <cmath>
#include <limits>
#include <random>

#include <gtest/gtest.h>

#include "mesh_test_support.hpp"

namespace {

using vola::Box;
using vola::Point;
using vola::Quantizer;
using vola::Voxel;

constexpr double kInf = std::numeric_limits<double>::infinity();

std::vector<std::pair<const char*, Quantizer>> quantizers() {
  return {
      {"toolkit depth 1", Quantizer::toolkit({{0, 0, 0}, {1, 1, 1}}, 1)},
      {"toolkit depth 2, flat", Quantizer::toolkit({{-3, 2, 10}, {5, 4, 10}}, 2)},
      {"toolkit depth 3, offset", Quantizer::toolkit({{1000.5, 2000.25, -7}, {1010.5, 2003, -1}}, 3)},
      {"grid depth 2", Quantizer::grid({-1, -1, -1}, 0.13, 2)},
      {"grid depth 3, UTM", Quantizer::grid({500000, 4000000, 100}, 0.5, 3)},
      {"toolkit depth 2, near the largest double", Quantizer::toolkit({{0, 0, -1e308}, {1, 1, 0}}, 2)},
  };
}

bool boxes_meet(const Box& a, const Box& b) {
  for (int k = 0; k < 3; ++k)
    if (a.max[k] < b.min[k] || b.max[k] < a.min[k]) return false;
  return true;
}

TEST(CellBox, NeighboursShareFacesAndBordersFollowTheMode) {
  for (const auto& [name, q] : quantizers()) {
    SCOPED_TRACE(name);
    const std::uint32_t side = vola::side_of(q.depth());
    const bool toolkit = q.frame().quantization == vola::Quantization::toolkit;
    for (std::uint32_t i = 0; i < side; ++i) {
      const Box b = q.cell_box({i, i, i});
      for (int a = 0; a < 3; ++a) {
        EXPECT_LT(b.min[a], b.max[a]);
        // (center() multiplies before dividing and overflows near the largest double.)
        const Point c = q.center({i, i, i});
        if (std::isfinite(c[a])) {
          EXPECT_TRUE(b.min[a] <= c[a] && c[a] <= b.max[a]);
        }
        if (i + 1 < side) {
          Voxel next{i, i, i};
          (a == 0 ? next.x : a == 1 ? next.y : next.z) += 1;
          EXPECT_EQ(b.max[a], q.cell_box(next).min[a]) << "axis " << a << " voxel " << i;
        }
      }
      // Toolkit mode clamps, so its border voxels reach to infinity.
      EXPECT_EQ(std::isinf(b.min[0]), toolkit && i == 0);
      EXPECT_EQ(std::isinf(b.max[2]), toolkit && i == side - 1);
    }
  }
  const Quantizer point = Quantizer::toolkit({{2, 2, 2}, {2, 2, 2}}, 1);
  EXPECT_EQ(point.cell_box({0, 0, 0}), (Box{{-kInf, -kInf, -kInf}, {kInf, kInf, kInf}}));
  const Box other = point.cell_box({1, 0, 0});
  EXPECT_GT(other.min[0], other.max[0]);
  // An axis whose (min + Lmax) - min rounds to 0: to_voxel puts x <= 1e20 in voxel 0
  // and x > 1e20 in voxel 3; the voxels between collapse onto the plane x = 1e20.
  const Quantizer flat = Quantizer::toolkit({{1e20, 0, 0}, {1e20, 1, 1}}, 1);
  Voxel v;
  ASSERT_TRUE(flat.to_voxel({1e20, 0.5, 0.5}, v));
  EXPECT_EQ(v.x, 0u);
  ASSERT_TRUE(flat.to_voxel({2e20, 0.5, 0.5}, v));
  EXPECT_EQ(v.x, 3u);
  EXPECT_EQ(flat.cell_box({0, 0, 0}).max[0], 1e20);
  EXPECT_EQ(flat.cell_box({3, 0, 0}).min[0], 1e20);
  EXPECT_EQ(flat.cell_box({1, 0, 0}).min[0], 1e20);
  EXPECT_EQ(flat.cell_box({1, 0, 0}).max[0], 1e20);
  Voxel first, last;
  ASSERT_TRUE(flat.voxel_range({{1e20, 0.2, 0.2}, {1e20, 0.3, 0.3}}, first, last));
  EXPECT_EQ(first.x, 0u);
  EXPECT_EQ(last.x, 3u);
}

TEST(CellBox, PointsLieInTheBoxOfTheirVoxel) {
  std::mt19937_64 rng(41);
  for (const auto& [name, q] : quantizers()) {
    SCOPED_TRACE(name);
    const vola::Frame f = q.frame();
    const double extent = f.voxel_size * vola::side_of(q.depth());
    std::uniform_real_distribution<double> unit(-0.1, 1.1);
    for (int i = 0; i < 20000; ++i) {
      const Point p{f.origin[0] + unit(rng) * extent, f.origin[1] + unit(rng) * extent,
                    f.origin[2] + unit(rng) * extent};
      Voxel v;
      if (!q.to_voxel(p, v)) continue;
      const Box b = q.cell_box(v);
      for (int a = 0; a < 3; ++a) {
        const double tolerance = 1e-12 * (std::abs(p[a]) + f.voxel_size);
        EXPECT_TRUE(b.min[a] - tolerance <= p[a] && p[a] <= b.max[a] + tolerance) << p[a] << " axis " << a;
      }
    }
  }
}

TEST(VoxelRange, CoversEveryVoxelABoxTouchesAndLittleMore) {
  std::mt19937_64 rng(42);
  for (const auto& [name, q] : quantizers()) {
    SCOPED_TRACE(name);
    const vola::Frame f = q.frame();
    const std::uint32_t side = vola::side_of(q.depth());
    const double extent = f.voxel_size * side;
    std::uniform_real_distribution<double> unit(-0.2, 1.2), size(0.0, 0.3);
    std::uniform_int_distribution<std::uint32_t> pick(0, side - 1);
    for (int i = 0; i < 300; ++i) {
      Box box;
      for (int a = 0; a < 3; ++a) {
        box.min[a] = f.origin[a] + unit(rng) * extent;
        box.max[a] = box.min[a] + (i % 4 == 0 ? 0.0 : size(rng) * extent);
      }
      if (i % 3 == 1) {  // faces exactly on cell faces
        const Box cell = q.cell_box({pick(rng), pick(rng), pick(rng)});
        for (int a = 0; a < 3; ++a)
          if (std::isfinite(cell.max[a])) box.min[a] = box.max[a] = cell.max[a];
      }
      vola_test::XyzSet touched;
      for (std::uint32_t z = 0; z < side; ++z)
        for (std::uint32_t y = 0; y < side; ++y)
          for (std::uint32_t x = 0; x < side; ++x)
            if (boxes_meet(box, q.cell_box({x, y, z}))) touched.insert({x, y, z});
      Voxel first, last;
      const bool any = q.voxel_range(box, first, last);
      if (!any) {
        EXPECT_TRUE(touched.empty()) << i;
        continue;
      }
      if (touched.empty()) continue;  // a toolkit grid always has a nearest voxel; grid mode may overshoot
      const Voxel lo = vola_test::to_voxel(*touched.begin());
      Voxel hi = lo, low = lo;
      for (const auto& t : touched) {
        low = {std::min(low.x, t[0]), std::min(low.y, t[1]), std::min(low.z, t[2])};
        hi = {std::max(hi.x, t[0]), std::max(hi.y, t[1]), std::max(hi.z, t[2])};
      }
      // A superset, by at most one voxel per side.
      EXPECT_TRUE(first.x <= low.x && first.y <= low.y && first.z <= low.z) << i;
      EXPECT_TRUE(last.x >= hi.x && last.y >= hi.y && last.z >= hi.z) << i;
      EXPECT_TRUE(low.x - first.x <= 1 && low.y - first.y <= 1 && low.z - first.z <= 1) << i;
      EXPECT_TRUE(last.x - hi.x <= 1 && last.y - hi.y <= 1 && last.z - hi.z <= 1)
          << i << ": last " << last.x << " " << last.y << " " << last.z << ", touched up to " << hi.x << " " << hi.y
          << " " << hi.z << ", box " << box.min[0] << " " << box.min[1] << " " << box.min[2] << " .. " << box.max[0]
          << " " << box.max[1] << " " << box.max[2];
    }
  }
}

TEST(VoxelRange, EdgeCases) {
  const Quantizer grid = Quantizer::grid({0, 0, 0}, 1.0, 1);
  Voxel first, last;
  EXPECT_FALSE(grid.voxel_range({{10, 0, 0}, {11, 1, 1}}, first, last));
  EXPECT_FALSE(grid.voxel_range({{1, 1, 1}, {0, 0, 0}}, first, last));  // empty
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(grid.voxel_range({{nan, 0, 0}, {1, 1, 1}}, first, last));
  ASSERT_TRUE(grid.voxel_range({{-kInf, -kInf, -kInf}, {kInf, kInf, kInf}}, first, last));
  EXPECT_EQ(first, (Voxel{0, 0, 0}));
  EXPECT_EQ(last, (Voxel{3, 3, 3}));
  const Quantizer toolkit = Quantizer::toolkit({{0, 0, 0}, {1, 1, 1}}, 1);
  ASSERT_TRUE(toolkit.voxel_range({{5, 5, 5}, {6, 6, 6}}, first, last));  // clamps, like to_voxel
  EXPECT_EQ(first, (Voxel{3, 3, 3}));
  EXPECT_EQ(last, (Voxel{3, 3, 3}));
  const Quantizer point = Quantizer::toolkit({{2, 2, 2}, {2, 2, 2}}, 2);
  ASSERT_TRUE(point.voxel_range({{-9, -9, -9}, {9, 9, 9}}, first, last));
  EXPECT_EQ(first, (Voxel{0, 0, 0}));
  EXPECT_EQ(last, (Voxel{0, 0, 0}));
}

}  // namespace
