// The map against the exact reference model (reference_map.hpp) on random scenes full of
// the cases a traversal gets wrong: rays through edges and corners, along grid planes,
// origins on corners, zero-length rays; and the batch, max-range and NaN rules.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "reference_map.hpp"
#include "vola/map/occupancy_map.hpp"

namespace {

using vola::map::OccupancyMap;
using vola::map::VoxelIndex;
using namespace vola_map_test;

// A point that sits on a grid feature relative to `origin` now and then.
Units random_point(std::mt19937_64& rng, const Units& origin) {
  std::uniform_int_distribution<std::int64_t> coord(-320, 320), kind(0, 9), small(-40, 40);
  Units p{coord(rng), coord(rng), coord(rng)};
  switch (kind(rng)) {
    case 0: for (auto& v : p) v -= v % kVoxelUnits; break;               // a cell corner
    case 1: p[1] = origin[1]; break;                                    // parallel to a plane
    case 2: p[1] = origin[1]; p[2] = origin[2]; break;                  // along an axis
    case 3: { const auto k = small(rng); p = {origin[0] + k, origin[1] + k, origin[2] - k}; break; }  // diagonal
    case 4: { const auto k = small(rng); p = {origin[0] + k, origin[1] - k, origin[2]}; break; }      // through edges
    case 5: if (small(rng) < -30) p = origin; break;                    // zero length, now and then
    default: break;
  }
  return p;
}

Units random_origin(std::mt19937_64& rng) {
  std::uniform_int_distribution<std::int64_t> coord(-96, 96), kind(0, 3);
  Units o{coord(rng), coord(rng), coord(rng)};
  if (kind(rng) == 0) o = {0, 0, 0};                                    // a corner, as KITTI's sensor
  else if (kind(rng) == 1) o[0] -= o[0] % kVoxelUnits;                  // on a plane
  return o;
}

void expect_same(const OccupancyMap& map, const ReferenceMap& reference, const std::string& what) {
  const auto voxels = map.voxels();
  ASSERT_EQ(voxels.size(), reference.cells().size()) << what;
  auto it = reference.cells().begin();
  for (const auto& [v, value] : voxels) {
    ASSERT_EQ(v, it->first) << what;
    // The map holds log-odds in 16-bit levels (detail/log_odds_levels.hpp): at most 8
    // updates here put a value within 3e-6 + 8 * 5e-7 of the float sum, well inside half a
    // step (4.4e-5); the decision is the same.
    ASSERT_NEAR(value, it->second, map.levels().step() / 2) << what << " at " << v.i << " " << v.j << " " << v.k;
    ASSERT_EQ(map.occupied(value), map.occupied(it->second)) << what << " at " << v.i << " " << v.j << " " << v.k;
    ++it;
  }
}

TEST(OccupancyMap, DefaultsAreOctoMapsLogOdds) {
  const vola::map::SensorModel m;
  EXPECT_NEAR(m.hit, 0.8473, 1e-4);
  EXPECT_NEAR(m.miss, -0.4055, 1e-4);
  // OctoMap's documentation rounds these to -2 and 3.5; log(0.971 / 0.029) is 3.511.
  EXPECT_NEAR(m.clamp_min, -2.0000, 1e-4);
  EXPECT_NEAR(m.clamp_max, 3.5110, 1e-4);
  EXPECT_EQ(m.occupied_at, 0.0f);
}

TEST(OccupancyMap, LogOddsLevelsAreExactWhereTheyMustBe) {
  const OccupancyMap map(kVoxelSize);
  const vola::map::SensorModel m;
  const auto& levels = map.levels();
  ASSERT_GE(levels.levels(), 32768u);
  // Every level reads back from its float (a saved map is restored exactly), and the
  // clamps are the model's own floats.
  for (std::uint32_t q = 0; q <= levels.levels(); ++q)
    ASSERT_EQ(levels.level_of(levels.value(static_cast<std::uint16_t>(q))), q) << q;
  EXPECT_EQ(levels.value(0), m.clamp_min);
  EXPECT_EQ(levels.value(static_cast<std::uint16_t>(levels.levels())), m.clamp_max);
  // Hit and miss are whole steps to within 5e-7, and 0 lies within 3e-6 of a level.
  EXPECT_NEAR(levels.value(levels.hit(levels.zero())), m.hit, 4e-6);
  EXPECT_NEAR(levels.value(levels.miss(levels.zero())), m.miss, 4e-6);
  const auto q = levels.level_of(1.0f);
  EXPECT_NEAR(levels.value(levels.hit(q)) - levels.value(q), m.hit, 5e-7);
  EXPECT_NEAR(levels.value(levels.miss(q)) - levels.value(q), m.miss, 5e-7);
}

TEST(OccupancyMap, ReferenceOnAHandCheckedRay) {
  // 0.1 m -> 1.1 m along x at 0.25 m voxels: passes cells 0..3, ends in cell 4.
  const auto passed = ReferenceMap::passed({6, 8, 8}, {70, 8, 8});
  ASSERT_EQ(passed.size(), 4u);
  for (std::int32_t i = 0; i < 4; ++i) EXPECT_EQ(passed[static_cast<std::size_t>(i)], (VoxelIndex{i, 0, 0}));
  // A diagonal through the corner (16,16): cells (0,0) and (1,1) only, not (0,1) or (1,0).
  const auto diagonal = ReferenceMap::passed({8, 8, 8}, {40, 40, 8});
  EXPECT_EQ(diagonal, (std::vector<VoxelIndex>{{0, 0, 0}, {1, 1, 0}}));
}

TEST(OccupancyMap, EqualsTheExactReferenceOnRandomScenes) {
  std::mt19937_64 rng(22);
  for (int scene = 0; scene < 12; ++scene) {
    OccupancyMap map(kVoxelSize), serial(kVoxelSize);
    ReferenceMap reference;
    for (int s = 0; s < 8; ++s) {
      UnitScan scan{random_origin(rng), {}};
      for (int n = 0; n < 300; ++n) scan.points.push_back(random_point(rng, scan.origin));
      reference.insert(scan);
      map.insert_scan(metres(scan.points), metres(scan.origin), 0.0, 2);
      serial.insert_scan(metres(scan.points), metres(scan.origin), 0.0, 1);
    }
    expect_same(map, reference, "scene " + std::to_string(scene));
    expect_same(serial, reference, "scene " + std::to_string(scene) + ", one thread");
    // Whatever the thread count, the same levels bit for bit.
    EXPECT_EQ(map.voxels(), serial.voxels()) << "scene " << scene;
  }
}

TEST(OccupancyMap, OneScanIsOneBatchNotTwoInserts) {
  // Two rays along x from the origin's voxel: the first ends in voxel 2, which the second
  // passes. In one scan voxel 2 is hit only; voxels 0 and 1, passed by both, get one miss.
  const std::vector<double> scan{0.6, 0.1, 0.1, 1.1, 0.1, 0.1};
  OccupancyMap batch(kVoxelSize);
  batch.insert_scan(scan, {0.1, 0.1, 0.1});
  const vola::map::SensorModel m;
  // Log-odds within 1e-5 of the float sums: the map's 16-bit levels (see above).
  const auto near = [](std::optional<float> value, float expected) {
    return value && std::abs(*value - expected) < 1e-5f;
  };
  EXPECT_TRUE(near(batch.log_odds({2, 0, 0}), m.hit));
  EXPECT_TRUE(near(batch.log_odds({0, 0, 0}), m.miss));
  EXPECT_TRUE(near(batch.log_odds({3, 0, 0}), m.miss));
  EXPECT_TRUE(near(batch.log_odds({4, 0, 0}), m.hit));
  // The same scan twice: two updates each.
  batch.insert_scan(scan, {0.1, 0.1, 0.1});
  EXPECT_TRUE(near(batch.log_odds({2, 0, 0}), m.hit + m.hit));
  EXPECT_TRUE(near(batch.log_odds({0, 0, 0}), m.miss + m.miss));
  // Its rays as two scans: voxel 2 is hit by one and passed by the other.
  OccupancyMap apart(kVoxelSize);
  apart.insert_scan(std::span(scan).first(3), {0.1, 0.1, 0.1});
  apart.insert_scan(std::span(scan).last(3), {0.1, 0.1, 0.1});
  EXPECT_TRUE(near(apart.log_odds({2, 0, 0}), m.hit + m.miss));
  EXPECT_TRUE(near(apart.log_odds({0, 0, 0}), m.miss + m.miss));
}

TEST(OccupancyMap, ClampsAtOctoMapsBounds) {
  OccupancyMap map(kVoxelSize);
  const vola::map::SensorModel m;
  for (int n = 0; n < 10; ++n) map.insert_scan(std::vector<double>{1.1, 0.1, 0.1}, {0.1, 0.1, 0.1});
  EXPECT_EQ(map.log_odds({4, 0, 0}), m.clamp_max);
  EXPECT_EQ(map.log_odds({1, 0, 0}), m.clamp_min);
  EXPECT_TRUE(map.occupied(*map.log_odds({4, 0, 0})));
  EXPECT_FALSE(map.occupied(*map.log_odds({1, 0, 0})));
  EXPECT_EQ(map.log_odds({9, 9, 9}), std::nullopt);
}

TEST(OccupancyMap, MaxRangeCutsTheRayWithoutAHit) {
  // 8 m along x from 0.125; cut at 2 m, at x = 2.125, in voxel 8: free 0..7, nothing hit.
  OccupancyMap map(kVoxelSize);
  const auto report = map.insert_scan(std::vector<double>{8.125, 0.1, 0.1}, {0.125, 0.1, 0.1}, 2.0);
  EXPECT_EQ(report.cut, 1u);
  EXPECT_EQ(report.hit_voxels, 0u);
  EXPECT_EQ(map.size(), 8u);
  for (std::int32_t i = 0; i < 8; ++i) EXPECT_NEAR(map.log_odds({i, 0, 0}).value_or(9.0f), map.model().miss, 1e-5) << i;
  // Within range: the usual ray and hit.
  const auto within = map.insert_scan(std::vector<double>{1.1, 0.1, 0.1}, {0.125, 0.1, 0.1}, 2.0);
  EXPECT_EQ(within.cut, 0u);
  EXPECT_EQ(within.hit_voxels, 1u);
}

TEST(OccupancyMap, SkipsAndCountsPointsThatAreNotFiniteOrOutside) {
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  OccupancyMap map(kVoxelSize);
  const auto report = map.insert_scan(std::vector<double>{nan, 0, 0, 1, inf, 1, 1e9, 0, 0, 1.1, 0.1, 0.1},
                                      {0.1, 0.1, 0.1});
  EXPECT_EQ(report.points, 4u);
  EXPECT_EQ(report.not_finite, 2u);
  EXPECT_EQ(report.outside, 1u);
  EXPECT_EQ(report.hit_voxels, 1u);
  EXPECT_EQ(map.size(), 5u);
  EXPECT_THROW(map.insert_scan(std::vector<double>{1, 1, 1}, {nan, 0, 0}), vola::InvalidArgument);
  EXPECT_THROW(map.insert_scan(std::vector<double>{1, 1, 1}, {0, 0, 0}, -1.0), vola::InvalidArgument);
  EXPECT_THROW(OccupancyMap(0.0), vola::OptionError);
}

TEST(OccupancyMap, PackingRoundTripsTheWholeIndexRange) {
  for (const std::int32_t v : {-vola::map::kIndexLimit, -1, 0, 1, vola::map::kIndexLimit - 1}) {
    const VoxelIndex index{v, -v - 1, v / 2};
    EXPECT_EQ(OccupancyMap::unpack(OccupancyMap::pack(index)), index);
  }
}

}  // namespace
