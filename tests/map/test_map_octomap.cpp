// vola's map against OctoMap 1.9 (liboctomap, a test-only dependency) after the same
// scans: OcTree(R).insertPointCloud(cloud, origin, max_range) on random scenes and on
// real KITTI scans, every voxel either one knows compared. Both get the same float
// coordinates. Where they can differ: OctoMap walks a float-normalized direction with
// accumulated crossing times and steps one axis at a time at ties, and quantizes by
// floor(x * (1/R)) where vola computes floor(x / R).
#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <random>

#include "io_test_data.hpp"
#include "octomap_agreement.hpp"
#include "vola/io/input.hpp"

namespace {

using vola::map::OccupancyMap;
using vola_map_test::Agreement;

struct Scan {
  std::vector<double> xyz;  // float values, as OctoMap stores them
  vola::Point origin{0, 0, 0};
};

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// Inserts the scans into both and compares; prints the figures and the insertion times.
Agreement insert_both(const std::vector<Scan>& scans, double voxel_size, double max_range, const std::string& label) {
  OccupancyMap map(voxel_size);
  octomap::OcTree tree(voxel_size);
  double vola_seconds = 0, octomap_seconds = 0;
  std::size_t points = 0;
  for (const Scan& s : scans) {
    octomap::Pointcloud cloud;
    for (std::size_t n = 0; n < s.xyz.size(); n += 3)
      cloud.push_back(static_cast<float>(s.xyz[n]), static_cast<float>(s.xyz[n + 1]), static_cast<float>(s.xyz[n + 2]));
    const octomap::point3d origin(static_cast<float>(s.origin[0]), static_cast<float>(s.origin[1]),
                                  static_cast<float>(s.origin[2]));
    auto start = std::chrono::steady_clock::now();
    // OctoMap's "no limit" is a negative max range.
    tree.insertPointCloud(cloud, origin, max_range > 0 ? max_range : -1.0);
    octomap_seconds += seconds_since(start);
    start = std::chrono::steady_clock::now();
    map.insert_scan(s.xyz, s.origin, max_range);
    vola_seconds += seconds_since(start);
    points += cloud.size();
  }
  const Agreement a = vola_map_test::compare(map, tree);
  std::printf("[%s] R=%g max_range=%g, %zu points: %s\n  insert: vola %.3f s, OctoMap %.3f s\n", label.c_str(),
              voxel_size, max_range, points, a.summary().c_str(), vola_seconds, octomap_seconds);
  return a;
}

std::vector<Scan> random_scenes(std::uint64_t seed, int scans, int points) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<float> origin(-2.0f, 2.0f), offset(-12.0f, 12.0f);
  std::vector<Scan> out;
  for (int s = 0; s < scans; ++s) {
    Scan scan;
    scan.origin = {origin(rng), origin(rng), origin(rng)};
    for (int n = 0; n < points; ++n)
      for (int a = 0; a < 3; ++a)
        scan.xyz.push_back(static_cast<float>(scan.origin[static_cast<std::size_t>(a)] + offset(rng)));
    out.push_back(std::move(scan));
  }
  return out;
}

void expect_agreement(const Agreement& a) {
  EXPECT_GT(a.both, 0u);
  // The bar for decisions; identical is the aim (the summary above says how close).
  EXPECT_GE(a.decision_fraction(), 0.995) << a.summary();
  EXPECT_GE(static_cast<double>(a.same_log_odds), 0.99 * static_cast<double>(a.both)) << a.summary();
}

TEST(MapAgainstOctoMap, SensorModelIsOctoMapsBitForBit) {
  const octomap::OcTree tree(0.1);
  const vola::map::SensorModel m;
  EXPECT_EQ(m.hit, tree.getProbHitLog());
  EXPECT_EQ(m.miss, tree.getProbMissLog());
  EXPECT_EQ(m.clamp_min, tree.getClampingThresMinLog());
  EXPECT_EQ(m.clamp_max, tree.getClampingThresMaxLog());
  EXPECT_EQ(m.occupied_at, tree.getOccupancyThresLog());
}

TEST(MapAgainstOctoMap, RandomScenes) {
  // 0.25 is a power of two: floor(x / R) and OctoMap's floor(x * (1/R)) agree exactly.
  expect_agreement(insert_both(random_scenes(7, 10, 2000), 0.25, 0.0, "random"));
  expect_agreement(insert_both(random_scenes(8, 10, 2000), 0.25, 8.0, "random, max range"));
  expect_agreement(insert_both(random_scenes(9, 10, 2000), 0.1, 0.0, "random"));
}

TEST(MapAgainstOctoMap, KittiScans) {
  const auto files = vola_io_test::files_ending(vola_io_test::data_dir() / "kitti", ".bin");
  if (files.empty()) GTEST_SKIP() << "no KITTI scans under " << vola_io_test::data_dir();
  for (const auto& file : files) {
    const vola::io::Input input = vola::io::read_input(file.string(), "auto", {});
    ASSERT_GT(input.cloud.size(), 1000u) << file;
    const std::vector<Scan> scans{{input.cloud.xyz, {0, 0, 0}}};
    expect_agreement(insert_both(scans, 0.2, 0.0, file.filename().string()));
    expect_agreement(insert_both(scans, 0.2, 30.0, file.filename().string()));
  }
}

}  // namespace
