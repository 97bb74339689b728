// Freezing a map into a state map and its occupied and free trees (voxels line up with the
// map's, log-odds kept exactly), and the scan list's format and errors.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>

#include "test_support.hpp"
#include "vola/file.hpp"
#include "vola/map/occupancy_map.hpp"
#include "vola/map/scan_list.hpp"
#include "vola/map/state_map.hpp"

namespace {

using vola::map::OccupancyMap;
using vola::map::VoxelState;

OccupancyMap small_map() {
  OccupancyMap map(0.5);
  // Rays in several directions from a sensor at negative coordinates: negative indices too.
  map.insert_scan(std::vector<double>{2.2, -1.3, 0.4, -3.1, 0.2, -0.7, 0.3, 2.9, 1.6, -2.0, -2.0, -2.0},
                  {-0.3, -0.2, 0.1});
  map.insert_scan(std::vector<double>{2.2, -1.3, 0.4, 1.0, 1.0, 1.0}, {-0.3, -0.2, 0.1});
  return map;
}

void expect_frozen(const OccupancyMap& map, VoxelState state) {
  const vola::Tree all = vola::map::freeze(map);
  const vola::Tree tree = state == VoxelState::occupied ? vola::map::occupied_tree(all) : vola::map::free_tree(all);
  EXPECT_FALSE(vola::map::is_state_map(tree));
  EXPECT_FALSE(tree.has_payload());
  const vola::AttributeColumn* column = tree.attributes().find("log_odds");
  ASSERT_NE(column, nullptr);
  EXPECT_EQ(column->type(), vola::ValueType::f32);
  const vola::Frame frame = tree.frame();
  EXPECT_EQ(frame.voxel_size, map.voxel_size());
  std::size_t expected = 0;
  for (const auto& [v, value] : map.voxels()) {
    if (map.occupied(value) != (state == VoxelState::occupied)) continue;
    ++expected;
    // The tree's voxel holding the map voxel's centre, found through the tree's own frame.
    const vola::Point centre{(v.i + 0.5) * map.voxel_size(), (v.j + 0.5) * map.voxel_size(),
                             (v.k + 0.5) * map.voxel_size()};
    const vola::Voxel t{static_cast<std::uint32_t>(std::floor((centre[0] - frame.origin[0]) / frame.voxel_size)),
                        static_cast<std::uint32_t>(std::floor((centre[1] - frame.origin[1]) / frame.voxel_size)),
                        static_cast<std::uint32_t>(std::floor((centre[2] - frame.origin[2]) / frame.voxel_size))};
    const auto rank = tree.rank(t);
    ASSERT_TRUE(rank.has_value()) << v.i << " " << v.j << " " << v.k;
    EXPECT_EQ(static_cast<float>(column->get(*rank)), value);
  }
  EXPECT_EQ(tree.voxel_count(), expected);
  // The origin is a multiple of R, so tree voxels are map voxels shifted by whole cells.
  for (const double o : frame.origin) EXPECT_EQ(std::remainder(o, map.voxel_size()), 0.0);
}

TEST(MapFreeze, OccupiedAndFreeTreesHoldTheMapsVoxelsAndLogOdds) {
  const OccupancyMap map = small_map();
  expect_frozen(map, VoxelState::occupied);
  expect_frozen(map, VoxelState::free);
}

TEST(MapFreeze, SurvivesAFileRoundTrip) {
  const OccupancyMap map = small_map();
  const vola::Tree tree = vola::map::freeze(map);
  const auto path = std::filesystem::temp_directory_path() / "vola_map_freeze_test.vol";
  vola::write(tree, path.string());
  const vola::Tree back = vola::read(path.string());
  std::filesystem::remove(path);
  EXPECT_TRUE(vola::map::is_state_map(back));
  EXPECT_EQ(back.voxel_count(), map.size());
  EXPECT_EQ(back.frame(), tree.frame());
  EXPECT_TRUE(std::ranges::equal(back.words(), tree.words()));
  ASSERT_NE(back.attributes().find("log_odds"), nullptr);
  const auto a = tree.attributes().find("log_odds")->bytes();
  const auto b = back.attributes().find("log_odds")->bytes();
  EXPECT_TRUE(std::equal(a.begin(), a.end(), b.begin(), b.end()));
}

TEST(ScanList, ParsesPosesAndResolvesPathsAgainstTheListsFolder) {
  const auto entries = vola::map::parse_scan_list(
      "# a comment\n\nscan0.bin 1 2 3 0 0 0 1\n/abs/scan1.ply 0 0 0 0 0 0.7071068 0.7071068\n", "/data/run", "list.txt");
  ASSERT_EQ(entries.size(), 2u);
  EXPECT_EQ(entries[0].file, "/data/run/scan0.bin");
  EXPECT_EQ(entries[0].line, 3);
  EXPECT_EQ(entries[1].file, "/abs/scan1.ply");
  // A quarter turn about z, then the translation.
  std::vector<double> p{1, 0, 0};
  entries[1].pose.apply(p);
  EXPECT_NEAR(p[0], 0.0, 1e-9);
  EXPECT_NEAR(p[1], 1.0, 1e-9);
  std::vector<double> q{1, 0, 0};
  entries[0].pose.apply(q);
  EXPECT_EQ(q, (std::vector<double>{2, 2, 3}));
}

TEST(ScanList, BadLinesAreErrorsThatNameTheLine) {
  const auto error_of = [](const std::string& text) {
    const auto e = vola_test::format_error_of([&] { vola::map::parse_scan_list(text, "", "list.txt"); });
    return e ? std::string(e->what()) : std::string("no error");
  };
  EXPECT_EQ(error_of("a.bin 0 0 0 0 0 0 1\nb.bin 0 0 0 0 0 1\n"),
            "list.txt: line 2: expected FILE tx ty tz qx qy qz qw (8 fields), got 7");
  EXPECT_EQ(error_of("a.bin 0 0 x 0 0 0 1\n"), "list.txt: line 1: tz is not a finite number: 'x'");
  EXPECT_EQ(error_of("a.bin 0 0 nan 0 0 0 1\n"), "list.txt: line 1: tz is not a finite number: 'nan'");
  EXPECT_EQ(error_of("\n\na.bin 0 0 0 0 0 0 2\n").substr(0, 40), "list.txt: line 3: the quaternion qx qy q");
  EXPECT_EQ(error_of("# nothing\n"), "list.txt: no scans listed");
  EXPECT_THROW(vola::map::read_scan_list("/nonexistent/list.txt"), vola::IoError);
}

}  // namespace
