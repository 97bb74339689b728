// vola view on a state map (vola map): the occupied voxels by default, the free ones as a
// layer of their own on request; a plain file has no free layer.
#include <gtest/gtest.h>

#include <filesystem>
#include <nlohmann/json.hpp>

#include "vola/builder.hpp"
#include "vola/error.hpp"
#include "vola/file.hpp"
#include "vola/map/occupancy_map.hpp"
#include "vola/map/state_map.hpp"
#include "vola/viewer/viewed_file.hpp"

namespace {

using vola::viewer::MapPart;
using vola::viewer::ViewedFile;

TEST(ViewerStateMap, ShowsTheOccupiedVoxelsAndTheFreeOnesOnRequest) {
  vola::map::OccupancyMap map(0.5);
  map.insert_scan(std::vector<double>{3.2, 0.3, 0.3, 0.3, 2.7, 0.3}, {0.1, 0.1, 0.1});
  const vola::Tree tree = vola::map::freeze(map);
  const auto counts = vola::map::state_counts(tree);
  ASSERT_EQ(counts.occupied, 2u);
  ASSERT_GT(counts.free, 0u);
  const auto path = std::filesystem::temp_directory_path() / "vola_viewer_state_map.vol";
  vola::write(tree, path.string());
  const ViewedFile occupied(path.string());
  const ViewedFile free(path.string(), MapPart::free);
  EXPECT_TRUE(occupied.is_state_map());
  EXPECT_EQ(occupied.tree().voxel_count(), counts.occupied);
  EXPECT_EQ(free.tree().voxel_count(), counts.free);
  EXPECT_EQ(occupied.metadata()["voxels"], counts.occupied);
  EXPECT_EQ(free.metadata()["name"], "vola_viewer_state_map.vol (free)");
  EXPECT_EQ(free.metadata()["state_map"], true);
  const auto plain = std::filesystem::temp_directory_path() / "vola_viewer_plain.vol";
  vola::write(vola::map::occupied_tree(tree), plain.string());
  EXPECT_FALSE(ViewedFile(plain.string()).is_state_map());
  EXPECT_THROW(ViewedFile(plain.string(), MapPart::free), vola::InvalidArgument);
  std::filesystem::remove(path);
  std::filesystem::remove(plain);
}

}  // namespace
