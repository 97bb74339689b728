// The distance field against brute force: every voxel of random scenes (and of a state
// map, whose free voxels are no obstacle) holds the exact distance to the nearest
// obstacle centre, capped; an update after a change equals a fresh field; the gradient
// points away from the obstacle.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "vola/builder.hpp"
#include "vola/error.hpp"
#include "vola/map/distance_field.hpp"
#include "vola/map/occupancy_map.hpp"
#include "vola/map/state_map.hpp"

namespace {

using vola::map::DistanceField;
using vola::map::GridBox;

std::vector<vola::Voxel> random_voxels(std::uint64_t seed, int count, std::uint32_t side) {
  std::mt19937_64 rng(seed);
  std::uniform_int_distribution<std::uint32_t> at(0, side - 1);
  std::vector<vola::Voxel> out;
  for (int n = 0; n < count; ++n) out.push_back({at(rng), at(rng), at(rng)});
  return out;
}

// min over obstacles of the distance between centres, capped, in voxels.
double brute_force(const std::vector<vola::Voxel>& obstacles, const std::array<std::int64_t, 3>& c, double cap) {
  double best = cap * cap;
  for (const vola::Voxel& o : obstacles) {
    const double dx = static_cast<double>(o.x) - static_cast<double>(c[0]);
    const double dy = static_cast<double>(o.y) - static_cast<double>(c[1]);
    const double dz = static_cast<double>(o.z) - static_cast<double>(c[2]);
    best = std::min(best, dx * dx + dy * dy + dz * dz);
  }
  return std::sqrt(best);
}

void expect_exact(const DistanceField& field, const std::vector<vola::Voxel>& obstacles, double cap_voxels) {
  const GridBox& b = field.box();
  for (std::int64_t z = b.lo[2]; z < b.hi[2]; ++z)
    for (std::int64_t y = b.lo[1]; y < b.hi[1]; ++y)
      for (std::int64_t x = b.lo[0]; x < b.hi[0]; ++x)
        ASSERT_NEAR(field.voxels_at({x, y, z}), brute_force(obstacles, {x, y, z}, cap_voxels), 1e-5)
            << x << " " << y << " " << z;
}

}  // namespace

TEST(DistanceField, EveryVoxelHoldsTheExactCappedDistance) {
  for (std::uint64_t seed = 1; seed <= 4; ++seed) {
    const auto obstacles = random_voxels(seed, 12, 16);
    const vola::Tree tree = vola::build_from_voxels(obstacles, 2);  // 16^3, voxel size 1
    // A box smaller than the grid: obstacles outside it still count.
    const DistanceField field(tree, GridBox{{2, 3, 1}, {14, 12, 15}}, 5.5);
    expect_exact(field, obstacles, 5.5);
  }
}

// Cells past the grid's faces lie near the obstacles on them: the field was clipped to
// the grid, so a point a voxel below a map's lowest obstacle read max_distance ("far")
// while a sphere there collided.
TEST(DistanceField, CellsPastTheGridsFacesHoldTheirDistanceToo) {
  const std::vector<vola::Voxel> obstacles{{0, 0, 0}, {15, 7, 15}, {3, 0, 9}};
  const vola::Tree tree = vola::build_from_voxels(obstacles, 2);  // 16^3, voxel size 1
  const DistanceField by_default(tree, 3.0);                      // the voxels' box grown by 3
  EXPECT_EQ(by_default.box().lo, (std::array<std::int64_t, 3>{-3, -3, -3}));
  EXPECT_EQ(by_default.box().hi, (std::array<std::int64_t, 3>{19, 11, 19}));
  expect_exact(by_default, obstacles, 3.0);
  EXPECT_NEAR(by_default.voxels_at({-1, 0, 0}), 1.0, 1e-6);  // the voxel left of (0, 0, 0), outside the grid
  // A box asked far past the grid is kept max_distance beyond it: the rest is all cap.
  const DistanceField wide(tree, GridBox{{-10, -10, -10}, {30, 30, 30}}, 2.0);
  EXPECT_EQ(wide.box().lo, (std::array<std::int64_t, 3>{-2, -2, -2}));
  EXPECT_EQ(wide.box().hi, (std::array<std::int64_t, 3>{18, 18, 18}));
  expect_exact(wide, obstacles, 2.0);
  EXPECT_EQ(wide.voxels_at({-9, 0, 0}), 2.0f);
  EXPECT_THROW(DistanceField(tree, GridBox{{-10, 0, 0}, {-5, 4, 4}}, 2.0), vola::InvalidArgument);
}

TEST(DistanceField, AnUpdateEqualsAFreshField) {
  auto obstacles = random_voxels(9, 10, 16);
  DistanceField field(vola::build_from_voxels(obstacles, 2), GridBox{{0, 0, 0}, {16, 16, 16}}, 4.0);
  obstacles.push_back({8, 8, 8});
  obstacles.erase(obstacles.begin());  // one obstacle gone, one new
  const vola::Tree changed = vola::build_from_voxels(obstacles, 2);
  GridBox region{{8, 8, 8}, {9, 9, 9}};
  const auto gone = random_voxels(9, 1, 16)[0];
  for (int a = 0; a < 3; ++a) {
    const std::int64_t g = a == 0 ? gone.x : a == 1 ? gone.y : gone.z;
    region.lo[a] = std::min(region.lo[a], g);
    region.hi[a] = std::max(region.hi[a], g + 1);
  }
  field.update(changed, region);
  expect_exact(field, obstacles, 4.0);
}

TEST(DistanceField, AStateMapsFreeVoxelsAreNoObstacleAndTheGradientPointsAway) {
  vola::map::OccupancyMap map(1.0);
  map.insert_scan(std::vector<double>{6.5, 0.5, 0.5}, {0.5, 0.5, 0.5});  // free 0..5, hit 6
  const vola::Tree state = vola::map::freeze(map);
  const DistanceField field(state, 3.0);
  EXPECT_DOUBLE_EQ(field.distance({6.5, 0.5, 0.5}), 0.0);
  EXPECT_DOUBLE_EQ(field.distance({4.5, 0.5, 0.5}), 2.0);
  EXPECT_DOUBLE_EQ(field.distance({0.5, 0.5, 0.5}), 3.0);  // capped
  EXPECT_LT(field.gradient({4.5, 0.5, 0.5})[0], 0.0);       // away from the obstacle at +x
  EXPECT_THROW(DistanceField(state, -1.0), vola::InvalidArgument);
}
