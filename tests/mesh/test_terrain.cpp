// Terrain columns against a set of voxels filled one column at a time.
#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

#include <gtest/gtest.h>

#include "mesh_test_support.hpp"
#include "vola/error.hpp"
#include "vola/mesh/terrain.hpp"

namespace {

using vola::Quantizer;
using vola_mesh_test::XyzSet;

// Row of height z on the frame's grid (voxel k covers [origin + k*size, origin + (k+1)*size)),
// clamped to the grid.
std::uint32_t slow_row(const Quantizer& q, double z) {
  const vola::Frame f = q.frame();
  const double k = std::floor((z - f.origin[2]) / f.voxel_size);
  return static_cast<std::uint32_t>(std::clamp(k, 0.0, static_cast<double>(vola::side_of(q.depth()) - 1)));
}

XyzSet slow_columns(const vola::PointCloud& cloud, const Quantizer& q, double base, bool surface_only) {
  XyzSet out;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    vola::Voxel v;
    if (!q.to_voxel({cloud.xyz[3 * i], cloud.xyz[3 * i + 1], cloud.xyz[3 * i + 2]}, v)) continue;
    const std::uint32_t b = surface_only ? v.z : slow_row(q, base);
    for (std::uint32_t z = std::min(v.z, b); z <= std::max(v.z, b); ++z) out.insert({v.x, v.y, z});
  }
  return out;
}

// A rough height field of nx x ny cells of `cell` size.
vola::PointCloud height_field(std::mt19937_64& rng, int nx, int ny, double cell) {
  std::uniform_real_distribution<double> bump(-3.0, 3.0);
  vola::PointCloud cloud;
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      cloud.xyz.push_back(1000.0 + (i + 0.5) * cell);
      cloud.xyz.push_back(2000.0 + (j + 0.5) * cell);
      cloud.xyz.push_back(50.0 + 10.0 * std::sin(i * 0.3) * std::cos(j * 0.2) + bump(rng));
    }
  return cloud;
}

TEST(Terrain, ColumnsMatchTheSlowFill) {
  std::mt19937_64 rng(31);
  for (double cell : {1.0, 0.3}) {  // 0.3: several cells per voxel column
    const vola::PointCloud cloud = height_field(rng, 23, 17, cell);
    const vola::Box bounds = cloud.bounds();
    const std::vector<Quantizer> quantizers = {
        Quantizer::toolkit({{bounds.min[0], bounds.min[1], 30.0}, {bounds.max[0], bounds.max[1], bounds.max[2]}}, 3),
        Quantizer::grid({1000.0, 2000.0, 30.0}, 0.5, 3),
        Quantizer::grid({1003.0, 2001.0, 45.0}, 0.25, 3),  // cuts some cells off
    };
    for (std::size_t k = 0; k < quantizers.size(); ++k)
      for (double base : {bounds.min[2], 33.3, 51.1, 80.0, -1000.0}) {
        for (bool surface_only : {false, true}) {
          vola::mesh::TerrainOptions options;
          options.base = base;
          options.surface_only = surface_only;
          vola::BuildReport report;
          const vola::Tree tree = vola::mesh::terrain_columns(cloud, quantizers[k], options, &report);
          const XyzSet expected = slow_columns(cloud, quantizers[k], base, surface_only);
          EXPECT_EQ(vola_test::voxel_set(tree), expected)
              << "cell " << cell << " quantizer " << k << " base " << base << " surface only " << surface_only;
          EXPECT_EQ(report.points_in, cloud.size());
          EXPECT_EQ(report.voxels, expected.size());
          EXPECT_EQ(*tree.stored_frame(), quantizers[k].frame());
        }
      }
  }
}

// A bigger field on a deeper grid: many columns under each block of every level.
TEST(Terrain, DeepGridMatchesTheSlowFill) {
  std::mt19937_64 rng(32);
  const vola::PointCloud cloud = height_field(rng, 150, 110, 0.7);
  for (int depth : {4, 5}) {
    const Quantizer q = Quantizer::grid({1000.0, 2000.0, 20.0}, 0.35, depth);
    vola::mesh::TerrainOptions options;
    options.base = 25.0;
    const vola::Tree tree = vola::mesh::terrain_columns(cloud, q, options);
    EXPECT_EQ(vola_test::voxel_set(tree), slow_columns(cloud, q, options.base, false)) << "depth " << depth;
  }
}

TEST(Terrain, PointsOutsideTheGridAreCounted) {
  vola::PointCloud cloud;
  cloud.xyz = {0.5, 0.5, 1.5, 10.0, 0.5, 1.0, 0.5, -3.0, 2.0, 0.5, 1.5, 0.2};
  vola::mesh::TerrainOptions options;
  options.base = 0.0;
  vola::BuildReport report;
  const vola::Tree tree = vola::mesh::terrain_columns(cloud, Quantizer::grid({0, 0, 0}, 1.0, 1), options, &report);
  EXPECT_EQ(report.points_outside, 2u);
  EXPECT_EQ(vola_test::voxel_set(tree), (XyzSet{{0, 0, 0}, {0, 0, 1}, {0, 1, 0}}));
}

TEST(Terrain, RefusesANonFiniteBase) {
  vola::PointCloud cloud;
  cloud.xyz = {0.5, 0.5, 1.5};
  vola::mesh::TerrainOptions options;
  options.base = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(vola::mesh::terrain_columns(cloud, Quantizer::grid({0, 0, 0}, 1.0, 1), options), vola::InvalidArgument);
  options.surface_only = true;  // no base needed
  EXPECT_EQ(vola::mesh::terrain_columns(cloud, Quantizer::grid({0, 0, 0}, 1.0, 1), options).voxel_count(), 1u);
}

TEST(Terrain, RefusesColumnsOverTheLimit) {
  vola::PointCloud cloud;
  cloud.xyz = {0.5, 0.5, 63.5, 1.5, 0.5, 63.5};
  vola::mesh::TerrainOptions options;
  options.base = 0.0;
  options.max_voxels = 127;
  EXPECT_THROW(vola::mesh::terrain_columns(cloud, Quantizer::grid({0, 0, 0}, 1.0, 3), options), vola::InvalidArgument);
  options.max_voxels = 128;
  EXPECT_EQ(vola::mesh::terrain_columns(cloud, Quantizer::grid({0, 0, 0}, 1.0, 3), options).voxel_count(), 128u);
}

}  // namespace
