// Surface patches (patches.hpp) against the geometry they are made from: a flat floor is one
// patch with its exact normal and area; a voxelised slope (a staircase of faces) is one
// patch with the slope's normal and area, not stripes of axis-aligned faces.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "vola/audio/patches.hpp"
#include "vola/builder.hpp"

namespace {

using namespace vola;
using namespace vola::audio;

TEST(AudioPatches, AFloorIsOnePatchWithItsNormalAndArea) {
  std::vector<Voxel> voxels;
  for (std::uint32_t y = 0; y < 64; ++y)
    for (std::uint32_t x = 0; x < 64; ++x) voxels.push_back({x, y, 5});
  const Tree tree = build_from_voxels(voxels, 3);
  const VoxelMaterials materials(scene_material(0.9), tree);
  const SurfacePatches patches(tree, materials, leaf_blocks(tree));
  // Top, bottom and the four one-voxel edges.
  EXPECT_EQ(patches.patches().size(), 6u);
  const SurfacePatch* top = nullptr;
  for (const SurfacePatch& p : patches.patches())
    if (p.normal[2] > 0.5) top = &p;
  ASSERT_NE(top, nullptr);
  EXPECT_EQ(top->normal, (Point{0, 0, 1}));
  EXPECT_DOUBLE_EQ(top->area, 64.0 * 64.0);
  EXPECT_DOUBLE_EQ(top->centroid[2], 6.0);
  EXPECT_EQ(top->faces, 64u * 64u);
  const auto id = static_cast<std::int64_t>(top - patches.patches().data());
  EXPECT_EQ(patches.patch_of(Voxel{10, 20, 5}, 5), id);
  EXPECT_EQ(patches.patch_of(Voxel{10, 20, 5}, 0), -1) << "an inner face is not exposed";
  EXPECT_TRUE(patches.voxel_in_patch(Voxel{63, 63, 5}, static_cast<std::uint32_t>(id)));
}

TEST(AudioPatches, AVoxelisedSlopeIsOnePatchWithTheSlopesNormal) {
  // Solid ground under z = 4 + x / 2 over 64 x 64 voxels: steps two voxels long, one high.
  std::vector<Voxel> voxels;
  for (std::uint32_t y = 0; y < 64; ++y)
    for (std::uint32_t x = 0; x < 64; ++x)
      for (std::uint32_t z = 0; z <= 4 + x / 2; ++z) voxels.push_back({x, y, z});
  std::sort(voxels.begin(), voxels.end(), [](const Voxel& a, const Voxel& b) { return std::tie(a.x, a.y, a.z) < std::tie(b.x, b.y, b.z); });
  const Tree tree = build_from_voxels(voxels, 3);
  const VoxelMaterials materials(scene_material(0.9), tree);
  const SurfacePatches patches(tree, materials, leaf_blocks(tree));
  // The largest patch facing up (the ground's underside is as large, facing down).
  const SurfacePatch* up = nullptr;
  for (const SurfacePatch& p : patches.patches())
    if (p.normal[2] > 0.5 && (!up || p.area > up->area)) up = &p;
  ASSERT_NE(up, nullptr);
  const SurfacePatch& slope = *up;

  const Point expected{-0.5 / std::sqrt(1.25), 0.0, 1.0 / std::sqrt(1.25)};
  const double cosine = slope.normal[0] * expected[0] + slope.normal[1] * expected[1] + slope.normal[2] * expected[2];
  EXPECT_GT(cosine, std::cos(2.0 * std::numbers::pi / 180.0)) << "normal (" << slope.normal[0] << ", " << slope.normal[1]
                                                               << ", " << slope.normal[2] << ")";
  // The slope's area: 64 voxels across, 64 * sqrt(1.25) up the slope (the edges of the
  // region may fall to other patches: within 10%).
  EXPECT_NEAR(slope.area / (64.0 * 64.0 * std::sqrt(1.25)), 1.0, 0.10);
}

}  // namespace
