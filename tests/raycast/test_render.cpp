// Rendering a converted survey gives a picture (pixels differ), the depth image matches
// single casts, and cameras refuse impossible settings.
#include <gtest/gtest.h>

#include <algorithm>
#include <utility>

#include "raycast_test_scenes.hpp"
#include "vola/builder.hpp"
#include "vola/error.hpp"
#include "vola/raycast/render.hpp"
#include "vola/raycast/world.hpp"

namespace {

using vola::raycast::PinholeCamera;

double variance(const std::vector<std::uint8_t>& v) {
  double sum = 0, sq = 0;
  for (const auto x : v) {
    sum += x;
    sq += static_cast<double>(x) * x;
  }
  const double n = static_cast<double>(v.size());
  return sq / n - (sum / n) * (sum / n);
}

TEST(Render, RealSurveyGivesAPictureMatchingSingleCasts) {
  auto tree = raycast_test::autzen_tree("pdal_autzen_trim.las", 5);
  if (!tree) {
    if (std::getenv("CI")) FAIL() << "shared data missing (CI is set)";
    GTEST_SKIP() << "shared data missing; set VOLA_SHARED";
  }
  const double side = tree->side();
  PinholeCamera camera;
  // Looking down at the middle of the occupied voxels from above and to the side.
  double centre[3] = {0, 0, 0};
  tree->for_each_voxel([&](const vola::Voxel& v) {
    centre[0] += v.x;
    centre[1] += v.y;
    centre[2] += v.z;
  });
  for (double& c : centre) c /= static_cast<double>(tree->voxel_count());
  camera.look_at = {centre[0], centre[1], centre[2]};
  camera.eye = {centre[0] - 0.05 * side, centre[1] - 0.05 * side, centre[2] + 0.05 * side};
  camera.width = 96;
  camera.height = 64;
  const vola::raycast::RayCaster caster(*tree);
  const auto image = vola::raycast::render(caster, camera, 2);
  ASSERT_EQ(image.rgb.size(), 96u * 64u * 3u);
  EXPECT_GT(image.hits, 96u * 64u / 10);
  EXPECT_GT(variance(image.rgb), 100.0);
  for (std::uint32_t row = 0; row < camera.height; ++row)
    for (std::uint32_t col = 0; col < camera.width; ++col) {
      const auto hit = caster.cast(camera.ray(col, row));
      const double depth = image.depth[row * camera.width + col];
      if (hit)
        EXPECT_EQ(depth, hit->t);
      else
        EXPECT_TRUE(std::isinf(depth));
    }
}

TEST(Render, WorldCameraMapsThroughTheFrame) {
  const vola::Frame frame{vola::Quantization::grid, {100, 200, 300}, 0.5};
  PinholeCamera world;
  world.eye = {101, 202, 303};
  world.look_at = {100, 200, 300};
  const auto grid = vola::raycast::world_camera_to_grid(frame, world);
  EXPECT_EQ(grid.eye, (vola::Point{2, 4, 6}));
  EXPECT_EQ(grid.look_at, (vola::Point{0, 0, 0}));
  EXPECT_EQ(vola::raycast::grid_to_world(frame, grid.eye), world.eye);
  const auto ray = vola::raycast::world_ray_to_grid(frame, {{100, 200, 300}, {1, 0, 0}, 3.0});
  EXPECT_EQ(ray.t_max, 6.0);
}

// The voxels' x (or z) range the default view's rays reach: every pixel cast.
std::pair<std::uint32_t, std::uint32_t> seen_range(const vola::Tree& tree, const PinholeCamera& camera, int axis) {
  const vola::raycast::RayCaster caster(tree);
  std::uint32_t lo = UINT32_MAX, hi = 0;
  for (std::uint32_t row = 0; row < camera.height; ++row)
    for (std::uint32_t col = 0; col < camera.width; ++col)
      if (const auto hit = caster.cast(camera.ray(col, row))) {
        const std::uint32_t v = axis == 0 ? hit->voxel.x : hit->voxel.z;
        lo = std::min(lo, v), hi = std::max(hi, v);
      }
  return {lo, hi};
}

// A long strip (a road, a power line corridor, las-rs's 800 x 28 m clip) and a tall
// tower: the default view sees both ends, whatever the image's aspect. The view placed
// at 0.8 x the longest extent, as before, cut the strip's ends off.
TEST(Render, TheDefaultViewFramesLongAndTallScenesWhole) {
  std::vector<vola::Voxel> strip, tower;
  for (std::uint32_t x = 0; x < 250; ++x)
    for (std::uint32_t y = 100; y < 116; ++y) strip.push_back({x, y, 10});
  for (std::uint32_t z = 0; z < 250; ++z)
    for (std::uint32_t x = 100; x < 116; ++x)
      for (std::uint32_t y = 100; y < 116; ++y) tower.push_back({x, y, z});
  const vola::Tree strip_tree = vola::build_from_voxels(strip, 4);
  const vola::Tree tower_tree = vola::build_from_voxels(tower, 4);
  for (const auto& [width, height] : {std::pair{160u, 120u}, std::pair{64u, 160u}, std::pair{200u, 50u}}) {
    PinholeCamera settings;
    settings.width = width, settings.height = height;
    const PinholeCamera s = vola::raycast::overview_camera(strip_tree, settings);
    EXPECT_EQ(s.width, width);
    const auto [x0, x1] = seen_range(strip_tree, s, 0);
    EXPECT_LE(x0, 8u) << width << "x" << height;
    EXPECT_GE(x1, 241u) << width << "x" << height;
    const auto [z0, z1] = seen_range(tower_tree, vola::raycast::overview_camera(tower_tree, settings), 2);
    EXPECT_LE(z0, 8u) << width << "x" << height;
    EXPECT_GE(z1, 241u) << width << "x" << height;
  }
}

TEST(Render, CameraRefusesImpossibleSettings) {
  PinholeCamera c;
  c.width = 0;
  EXPECT_THROW(c.check(), vola::InvalidArgument);
  c = {};
  c.vertical_fov_degrees = 180;
  EXPECT_THROW(c.check(), vola::InvalidArgument);
  c = {};
  c.look_at = c.eye;
  EXPECT_THROW(c.check(), vola::InvalidArgument);
  c = {};
  c.look_at = {0, 0, -1};
  c.up = {0, 0, -5};  // parallel to the view
  EXPECT_THROW(c.check(), vola::InvalidArgument);
  c = {};
  EXPECT_NO_THROW(c.check());
  // Orbit frame 0 is the camera itself; frame 2 of 4 is opposite the look-at point.
  c.eye = {10, 0, 5};
  c.look_at = {0, 0, 0};
  EXPECT_EQ(vola::raycast::orbit(c, 0, 4).eye, c.eye);
  const auto half = vola::raycast::orbit(c, 2, 4).eye;
  EXPECT_NEAR(half[0], -10, 1e-12);
  EXPECT_NEAR(half[1], 0, 1e-12);
  EXPECT_EQ(half[2], 5);
}

}  // namespace
