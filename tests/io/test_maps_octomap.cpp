// OctoMap .bt/.ot written by vola and read back by liboctomap itself, cell for cell;
// round trips vola -> OctoMap -> vola; free voxels through the MapVoxels API; placement
// of grids that do not line up with OctoMap's cells; damaged files refused with an error.
#include <octomap/AbstractOcTree.h>
#include <octomap/ColorOcTree.h>
#include <octomap/OcTree.h>

#include <array>
#include <cstring>
#include <fstream>
#include <limits>
#include <map>
#include <memory>
#include <sstream>

#include "export_test_support.hpp"
#include "map_test_support.hpp"
#include "vola/convert.hpp"
#include "vola/io/occupancy_maps.hpp"

namespace {

using vola_map_test::Cell;
using vola_map_test::cells_of;
using vola_map_test::random_map;
using vola_map_test::tree_of;

struct OctomapCells {
  double resolution = 0.0;
  std::map<Cell, float> occupied, free;
};

// Every leaf liboctomap reads, expanded to cells of the resolution.
OctomapCells read_with_liboctomap(const vola_test::fs::path& path) {
  std::unique_ptr<octomap::OcTree> tree;
  if (path.extension() == ".bt") {
    tree = std::make_unique<octomap::OcTree>(1.0);
    EXPECT_TRUE(tree->readBinary(path.string()));
  } else {
    std::unique_ptr<octomap::AbstractOcTree> read(octomap::AbstractOcTree::read(path.string()));
    EXPECT_TRUE(dynamic_cast<octomap::OcTree*>(read.get()));
    tree.reset(static_cast<octomap::OcTree*>(read.release()));
  }
  OctomapCells cells;
  if (!tree) return cells;
  cells.resolution = tree->getResolution();
  for (auto it = tree->begin_leafs(), end = tree->end_leafs(); it != end; ++it) {
    const octomap::OcTreeKey key = it.getIndexKey();
    const int span = 1 << (16 - it.getDepth());
    auto& target = tree->isNodeOccupied(*it) ? cells.occupied : cells.free;
    for (int z = 0; z < span; ++z)
      for (int y = 0; y < span; ++y)
        for (int x = 0; x < span; ++x)
          target[{key[0] + x - 32768, key[1] + y - 32768, key[2] + z - 32768}] = it->getLogOdds();
  }
  return cells;
}

std::set<Cell> keys_of(const std::map<Cell, float>& cells) {
  std::set<Cell> keys;
  for (const auto& entry : cells) keys.insert(entry.first);
  return keys;
}

using vola_map_test::kClampMax;
using vola_map_test::kClampMin;

TEST(OctomapExport, BtHoldsExactlyTheOccupiedVoxels) {
  vola_test::TempDir dir;
  for (std::uint64_t seed = 1; seed <= 12; ++seed) {
    const double size = std::array<double, 4>{0.1, 0.25, 0.05, 1.0}[seed % 4];
    const auto map = random_map(seed, size, seed % 3 == 0 ? 20000 : 300, 3000);
    const vola::Tree tree = tree_of(map.occupied, size, false);
    const auto path = dir / ("map" + std::to_string(seed) + ".bt");
    const auto report = vola::io::write_octomap(vola::io::map_voxels(tree), path.string());
    EXPECT_TRUE(report.warnings.empty()) << seed;
    EXPECT_EQ(report.shift, (vola::Point{0, 0, 0}));
    const OctomapCells read = read_with_liboctomap(path);
    EXPECT_EQ(read.resolution, size);
    EXPECT_EQ(keys_of(read.occupied), keys_of(map.occupied)) << "seed " << seed;
    EXPECT_TRUE(read.free.empty()) << seed;
    // OctoMap's own rule puts each vola voxel centre in the cell the file holds it in.
    octomap::OcTree rule(size);
    const vola::Quantizer quantizer = tree.quantizer();
    tree.for_each_voxel([&](const vola::Voxel& v) {
      const vola::Point c = quantizer.center(v);
      const octomap::OcTreeKey key = rule.coordToKey(c[0], c[1], c[2]);
      EXPECT_TRUE(read.occupied.count({key[0] - 32768, key[1] - 32768, key[2] - 32768}));
    });
  }
}

TEST(OctomapExport, OtKeepsTheLogOddsOfEveryVoxel) {
  vola_test::TempDir dir;
  for (std::uint64_t seed = 20; seed < 26; ++seed) {
    const auto map = random_map(seed, 0.2, 400, 4000);
    const vola::Tree tree = tree_of(map.occupied, 0.2, true);
    const auto path = dir / "map.ot";
    const auto report = vola::io::write_octomap(vola::io::map_voxels(tree), path.string());
    EXPECT_TRUE(report.log_odds);
    const OctomapCells read = read_with_liboctomap(path);
    ASSERT_EQ(keys_of(read.occupied), keys_of(map.occupied)) << seed;
    for (const auto& [cell, value] : map.occupied) EXPECT_FLOAT_EQ(read.occupied.at(cell), value);
  }
}

TEST(OctomapExport, OtWithoutLogOddsHoldsTheClampingMaximum) {
  vola_test::TempDir dir;
  const auto map = random_map(31, 0.5, 100, 500);
  vola::io::write_octomap(vola::io::map_voxels(tree_of(map.occupied, 0.5, false)), (dir / "m.ot").string());
  const OctomapCells read = read_with_liboctomap(dir / "m.ot");
  EXPECT_EQ(keys_of(read.occupied), keys_of(map.occupied));
  for (const auto& [cell, value] : read.occupied) EXPECT_FLOAT_EQ(value, kClampMax);
}

// The API a state map uses: occupied and free voxels on one frame.
TEST(OctomapExport, FreeVoxelsBecomeFreeLeaves) {
  vola_test::TempDir dir;
  for (std::uint64_t seed = 40; seed < 44; ++seed) {
    const auto map = random_map(seed, 0.1, 200, 5000);
    vola::io::MapVoxels voxels;
    voxels.frame = {vola::Quantization::grid, {-300 * 0.1, -300 * 0.1, -300 * 0.1}, 0.1};
    const auto add = [](const std::map<Cell, float>& cells, std::vector<vola::Voxel>& list, std::vector<float>& values) {
      for (const auto& [c, value] : cells) {
        list.push_back({static_cast<std::uint32_t>(c[0] + 300), static_cast<std::uint32_t>(c[1] + 300),
                        static_cast<std::uint32_t>(c[2] + 300)});
        values.push_back(value);
      }
    };
    add(map.occupied, voxels.occupied, voxels.occupied_log_odds);
    add(map.free, voxels.free, voxels.free_log_odds);
    const auto ot = vola::io::write_octomap(voxels, (dir / "s.ot").string());
    EXPECT_EQ(ot.occupied, map.occupied.size());
    EXPECT_EQ(ot.free, map.free.size());
    const OctomapCells with_values = read_with_liboctomap(dir / "s.ot");
    ASSERT_EQ(keys_of(with_values.occupied), keys_of(map.occupied)) << seed;
    ASSERT_EQ(keys_of(with_values.free), keys_of(map.free)) << seed;
    for (const auto& [cell, value] : map.free) EXPECT_FLOAT_EQ(with_values.free.at(cell), value);

    voxels.occupied_log_odds.clear();
    voxels.free_log_odds.clear();
    vola::io::write_octomap(voxels, (dir / "s.bt").string());
    const OctomapCells binary = read_with_liboctomap(dir / "s.bt");
    EXPECT_EQ(keys_of(binary.occupied), keys_of(map.occupied));
    EXPECT_EQ(keys_of(binary.free), keys_of(map.free));
    for (const auto& [cell, value] : binary.free) EXPECT_FLOAT_EQ(value, kClampMin);
  }
}

// `vola map --free` writes the free voxels as a second tree on its own origin.
TEST(OctomapExport, FreeTreeOnAnotherOriginLinesUp) {
  vola_test::TempDir dir;
  const auto map = random_map(50, 0.25, 300, 4000);
  const vola::Tree occupied = tree_of(map.occupied, 0.25, true), free = tree_of(map.free, 0.25, true);
  vola::io::write_octomap(vola::io::map_voxels(occupied, &free), (dir / "f.ot").string());
  const OctomapCells read = read_with_liboctomap(dir / "f.ot");
  EXPECT_EQ(keys_of(read.occupied), keys_of(map.occupied));
  EXPECT_EQ(keys_of(read.free), keys_of(map.free));

  const vola::Tree other_size = tree_of(map.free, 0.5, false);
  EXPECT_THROW(vola::io::map_voxels(occupied, &other_size), vola::InvalidArgument);
}

TEST(OctomapExport, AVoxelBothOccupiedAndFreeIsRefused) {
  vola_test::TempDir dir;
  vola::io::MapVoxels voxels;
  voxels.occupied = {{1, 2, 3}, {4, 5, 6}};
  voxels.free = {{0, 0, 0}, {4, 5, 6}};
  EXPECT_THROW(vola::io::write_octomap(voxels, (dir / "x.bt").string()), vola::InvalidArgument);
  EXPECT_FALSE(vola_test::fs::exists(dir / "x.bt"));
}

TEST(OctomapExport, RoundTripGivesTheSameVoxelsAndFrame) {
  vola_test::TempDir dir;
  for (std::uint64_t seed = 60; seed < 66; ++seed) {
    const double size = seed % 2 ? 0.05 : 0.5;
    const auto map = random_map(seed, size, 2000, 3000);
    for (const char* ext : {".bt", ".ot"}) {
      const vola::Tree tree = tree_of(map.occupied, size, true);
      const auto path = dir / (std::string("r") + ext);
      vola::io::write_octomap(vola::io::map_voxels(tree), path.string());
      const vola::Tree back = vola::convert(path.string(), {});
      EXPECT_EQ(back.frame().voxel_size, size);
      EXPECT_EQ(back.frame().origin, tree.frame().origin) << seed << ext;
      const auto cells = cells_of(back);
      ASSERT_EQ(keys_of(cells), keys_of(map.occupied)) << seed << ext;
      if (std::string(ext) == ".ot")
        for (const auto& [cell, value] : map.occupied) EXPECT_FLOAT_EQ(cells.at(cell), value);
      else
        EXPECT_EQ(back.attributes().size(), 0u);  // a .bt holds occupancy only
    }
  }
}

TEST(OctomapExport, OriginOffTheCellsMovesUnderHalfAVoxelWithAWarning) {
  vola_test::TempDir dir;
  vola::io::MapVoxels voxels;
  voxels.frame = {vola::Quantization::grid, {0.13, -0.07, 10.0}, 0.2};  // x, y off OctoMap's cells; z on them
  voxels.occupied = {{0, 0, 0}, {3, 1, 2}, {10, 10, 10}};
  const auto report = vola::io::write_octomap(voxels, (dir / "o.bt").string());
  ASSERT_EQ(report.warnings.size(), 1u);
  EXPECT_NE(report.warnings[0].find("not a multiple of the voxel size"), std::string::npos) << report.warnings[0];
  EXPECT_NEAR(report.shift[0], 0.2 - 0.13, 1e-12);  // 0.13 -> 0.2: the nearest cell corner
  EXPECT_NEAR(report.shift[1], 0.07, 1e-12);        // -0.07 -> 0
  EXPECT_EQ(report.shift[2], 0.0);
  const OctomapCells read = read_with_liboctomap(dir / "o.bt");
  EXPECT_EQ(keys_of(read.occupied), (std::set<Cell>{{1, 0, 50}, {4, 1, 52}, {11, 10, 60}}));
}

TEST(OctomapExport, SurveyCoordinatesMoveToOctomapsOriginWithAWarning) {
  vola_test::TempDir dir;
  vola::io::MapVoxels voxels;
  voxels.frame = {vola::Quantization::grid, {636000.0, 5048000.0, 120.0}, 1.0};  // UTM metres
  voxels.occupied = {{0, 0, 0}, {30000, 5, 7}};
  const auto report = vola::io::write_octomap(voxels, (dir / "u.bt").string());
  ASSERT_EQ(report.warnings.size(), 1u);
  EXPECT_NE(report.warnings[0].find("add it back"), std::string::npos) << report.warnings[0];
  EXPECT_EQ(report.shift, (vola::Point{-636000.0, -5048000.0, -120.0}));
  EXPECT_EQ(keys_of(read_with_liboctomap(dir / "u.bt").occupied), (std::set<Cell>{{0, 0, 0}, {30000, 5, 7}}));

  voxels.occupied.push_back({32768, 0, 0});  // beyond OctoMap's keys even from the corner
  EXPECT_THROW(vola::io::write_octomap(voxels, (dir / "w.bt").string()), vola::InvalidArgument);
}

TEST(OctomapImport, OtherVoxelSizesAreRefusedAndTheOwnAccepted) {
  vola_test::TempDir dir;
  const auto map = random_map(70, 0.25, 100, 300);
  vola::io::write_octomap(vola::io::map_voxels(tree_of(map.occupied, 0.25, false)), (dir / "m.bt").string());
  vola::ConvertOptions options;
  options.voxel_size = 0.25;
  EXPECT_EQ(keys_of(cells_of(vola::convert((dir / "m.bt").string(), options))), keys_of(map.occupied));
  options.voxel_size = 0.5;
  try {
    vola::convert((dir / "m.bt").string(), options);
    ADD_FAILURE() << "another voxel size was accepted";
  } catch (const vola::OptionError& e) {
    EXPECT_EQ(e.option(), "voxel_size");
    EXPECT_NE(std::string(e.what()).find("a map of 0.25"), std::string::npos) << e.what();
  }
}

// A pruned inner node expands to every cell it covers.
TEST(OctomapImport, PrunedNodesExpandToCells) {
  vola_test::TempDir dir;
  octomap::OcTree tree(0.5);
  for (octomap::key_type x = 32768; x < 32776; ++x)
    for (octomap::key_type y = 32768; y < 32776; ++y)
      for (octomap::key_type z = 32768; z < 32776; ++z) tree.updateNode(octomap::OcTreeKey(x, y, z), true);
  tree.updateNode(octomap::OcTreeKey(32760, 32768, 32769), true);
  tree.writeBinary((dir / "cube.bt").string());
  const vola::Tree back = vola::convert((dir / "cube.bt").string(), {});
  const auto cells = cells_of(back);
  EXPECT_EQ(cells.size(), 8u * 8u * 8u + 1u);
  EXPECT_TRUE(cells.count({-8, 0, 1}));
  EXPECT_TRUE(cells.count({7, 7, 7}));
  EXPECT_EQ(back.frame().origin, (vola::Point{-4.0, 0.0, 0.0}));
}

// A ColorOcTree .ot (octomap_server's and RTAB-Map's coloured maps) written by liboctomap:
// its occupied cells, log-odds and colours, pruned nodes expanded; every cut an error.
TEST(OctomapImport, ColorOcTreeCellsCarryTheirColours) {
  vola_test::TempDir dir;
  octomap::ColorOcTree tree(0.25);
  for (octomap::key_type x = 32768; x < 32770; ++x)
    for (octomap::key_type y = 32768; y < 32770; ++y)
      for (octomap::key_type z = 32768; z < 32770; ++z) {
        tree.updateNode(octomap::OcTreeKey(x, y, z), true);
        tree.setNodeColor(octomap::OcTreeKey(x, y, z), 200, 100, 50);
      }
  tree.updateNode(octomap::OcTreeKey(32780, 32768, 32768), true);
  tree.setNodeColor(octomap::OcTreeKey(32780, 32768, 32768), 10, 20, 30);
  tree.updateNode(octomap::OcTreeKey(32781, 32768, 32768), false);  // a free leaf: no voxel
  const auto path = dir / "colour.ot";
  ASSERT_TRUE(tree.write(path.string()));
  const vola::Tree back = vola::convert(path.string(), {});
  const auto cells = cells_of(back);
  EXPECT_EQ(cells.size(), 9u);
  EXPECT_EQ(back.frame().origin, (vola::Point{0.0, 0.0, 0.0}));
  const auto& attributes = back.attributes();
  ASSERT_NE(attributes.find("red"), nullptr);
  ASSERT_NE(attributes.find("log_odds"), nullptr);
  std::map<std::array<double, 3>, std::size_t> seen;
  back.for_each_voxel([&](const vola::Voxel& v) {
    const std::uint64_t rank = back.rank(v).value();
    const std::array<double, 3> rgb{attributes.find("red")->get(rank), attributes.find("green")->get(rank),
                                    attributes.find("blue")->get(rank)};
    EXPECT_EQ(rgb, (v.x == 12 ? std::array<double, 3>{10, 20, 30} : std::array<double, 3>{200, 100, 50})) << v.x;
    EXPECT_GT(attributes.find("log_odds")->get(rank), 0.0);
    ++seen[rgb];
  });
  EXPECT_EQ(seen.size(), 2u);
  const std::vector<std::uint8_t> bytes = vola_test::read_bytes(path);
  const auto header_end = std::string(bytes.begin(), bytes.end()).find("data\n") + 5;
  for (std::size_t cut = header_end + 1; cut < bytes.size(); ++cut) {
    const auto cut_path = dir / "cut.ot";
    vola_test::write_bytes(cut_path, std::vector<std::uint8_t>(bytes.begin(), bytes.begin() + cut));
    try {
      vola::convert(cut_path.string(), {});
      ADD_FAILURE() << "cut at " << cut << " accepted";
    } catch (const vola::Error& e) {
      EXPECT_NE(std::string(e.what()).find(cut_path.string()), std::string::npos) << e.what();
    }
  }
}

// ---- damaged files: an error naming the file, never a crash ----

std::string error_of(const vola_test::fs::path& path) {
  try {
    vola::convert(path.string(), {});
  } catch (const vola::Error& e) {
    return e.what();
  }
  return "";
}

TEST(OctomapImport, EveryCutOfAFileIsAnError) {
  vola_test::TempDir dir;
  const auto map = random_map(80, 0.1, 50, 200);
  for (const char* ext : {".bt", ".ot"}) {
    const auto path = dir / (std::string("whole") + ext);
    vola::io::write_octomap(vola::io::map_voxels(tree_of(map.occupied, 0.1, true)), path.string());
    const std::vector<std::uint8_t> bytes = vola_test::read_bytes(path);
    const auto header_end = std::string(bytes.begin(), bytes.end()).find("data\n") + 5;
    for (std::size_t cut = 0; cut < bytes.size(); cut += cut < header_end + 64 ? 1 : 7) {
      const auto cut_path = dir / (std::string("cut") + ext);
      vola_test::write_bytes(cut_path, std::vector<std::uint8_t>(bytes.begin(), bytes.begin() + cut));
      const std::string error = error_of(cut_path);
      // An .ot header alone (its data line complete or not) is a valid empty map.
      if (std::string(ext) == ".ot" && cut + 1 >= header_end && cut <= header_end) continue;
      EXPECT_NE(error, "") << ext << " cut at " << cut;
      EXPECT_NE(error.find(cut_path.string()), std::string::npos) << error;
    }
  }
}

TEST(OctomapImport, CraftedFilesAreRefused) {
  vola_test::TempDir dir;
  const auto write = [&](const std::string& name, const std::string& bytes) {
    std::ofstream(dir / name, std::ios::binary) << bytes;
    return dir / name;
  };
  const std::string bt = "# Octomap OcTree binary file\nid OcTree\nsize 9\nres 0.1\ndata\n";
  // Every child "has children" forever: liboctomap recurses past its 16 levels, and a
  // 200 KB file of these bytes made it crash (SIGSEGV, liboctomap 1.9.7).
  EXPECT_NE(error_of(write("deep.bt", bt + std::string(200000, '\xff'))).find("below OctoMap's 16 levels"),
            std::string::npos);
  // The root's eight children occupied leaves: 2^45 cells each, far beyond vola's limit.
  EXPECT_NE(error_of(write("huge.bt", bt + "\xaa\xaa")).find("occupied cells"), std::string::npos);
  EXPECT_NE(error_of(write("nores.bt", "# Octomap OcTree binary file\nid OcTree\nsize 1\ndata\n\x00\x00"))
                .find("resolution"),
            std::string::npos);
  EXPECT_NE(error_of(write("old.bt", std::string("\x03\x00\x00\x00", 4) + std::string(20, '\0'))).find("not an OctoMap file"),
            std::string::npos);
  EXPECT_NE(error_of(write("stamped.ot", "# Octomap OcTree file\nid OcTreeStamped\nsize 1\nres 0.1\ndata\n" + std::string(9, '\0')))
                .find("an .ot file of a OcTreeStamped"),
            std::string::npos);
  // A ColorOcTree node is 8 bytes (log-odds, r, g, b, child bits): 5 of them are cut short.
  EXPECT_NE(error_of(write("color.ot", "# Octomap OcTree file\nid ColorOcTree\nsize 1\nres 0.1\ndata\n" + std::string(5, '\0')))
                .find("ends inside a node"),
            std::string::npos);
  std::string nan_node(5, '\0');
  const float nan = std::numeric_limits<float>::quiet_NaN();
  std::memcpy(nan_node.data(), &nan, 4);
  EXPECT_NE(error_of(write("nan.ot", "# Octomap OcTree file\nid OcTree\nsize 1\nres 0.1\ndata\n" + nan_node)).find("not finite"),
            std::string::npos);
  EXPECT_NE(error_of(write("count.bt", "# Octomap OcTree binary file\nid OcTree\nsize 7\nres 0.1\ndata\n" + std::string("\x01\x00", 2)))
                .find("says 7 nodes"),
            std::string::npos);
  // A root without children: liboctomap makes it one occupied leaf of 2^48 cells, and vola
  // listed them one by one (minutes, then out of memory).
  const std::string bt_head = "# Octomap OcTree binary file\nid OcTree\nsize 17\nres 0.1\ndata\n";
  EXPECT_NE(error_of(write("bare.bt",
                           "# Octomap OcTree binary file\nid OcTree\nsize 1\nres 0.1\ndata\n" + std::string(2, '\0')))
                .find("the root has no children: liboctomap reads it as one occupied leaf of 2^48 cells"),
            std::string::npos);
  // Bytes after the tree: a .bt's stream under an .ot's first line read as an empty map,
  // and a file written twice read as its first copy. One occupied cell: fifteen inner
  // nodes (code 3) down to a leaf (code 2) at OctoMap's 16th level.
  std::string one_cell;
  for (int level = 0; level < 15; ++level) one_cell += std::string("\x03\x00", 2);
  one_cell += std::string("\x02\x00", 2);
  EXPECT_EQ(error_of(write("one.bt", bt_head + one_cell)), "");
  EXPECT_NE(error_of(write("twice.bt", bt_head + one_cell + bt_head + one_cell))
                .find(std::to_string(bt_head.size() + one_cell.size()) + " bytes follow the end of the tree"),
            std::string::npos);
  std::string free_root(4, '\0');  // an .ot root leaf of log-odds -2: free, its 64 bytes after it ignored
  const float minus_two = -2.0f;
  std::memcpy(free_root.data(), &minus_two, 4);
  EXPECT_NE(error_of(write("kind.ot", "# Octomap OcTree file\nid OcTree\nsize 1\nres 0.1\ndata\n" + free_root +
                                          std::string(1, '\0') + std::string(64, '\x55')))
                .find("64 bytes follow the end of the tree"),
            std::string::npos);
}

// A real survey: Autzen (UTM metres) at 2 m, far from OctoMap's 0, so shifted to its corner.
TEST(OctomapExport, RealSurveyVoxelsAreTheOccupiedCells) {
  const auto las = vola_export_test::data_dir() / "las" / "pdal_autzen-utm.las";
  VOLA_REQUIRE_DATA_FILE(las);
  vola_test::TempDir dir;
  vola::ConvertOptions options;
  options.voxel_size = 2.0;
  const vola::Tree tree = vola::convert(las.string(), options);
  const auto report = vola::io::write_octomap(vola::io::map_voxels(tree), (dir / "autzen.bt").string());
  ASSERT_EQ(report.warnings.size(), 1u);
  const OctomapCells read = read_with_liboctomap(dir / "autzen.bt");
  EXPECT_EQ(read.occupied.size(), tree.voxel_count());
  std::set<Cell> expected;
  const vola::Quantizer quantizer = tree.quantizer();
  tree.for_each_voxel([&](const vola::Voxel& v) {
    const vola::Point c = quantizer.center(v);
    Cell cell;
    for (int a = 0; a < 3; ++a) cell[a] = static_cast<std::int64_t>(std::floor((c[a] + report.shift[a]) / 2.0));
    expected.insert(cell);
  });
  EXPECT_EQ(keys_of(read.occupied), expected);
  EXPECT_TRUE(read.free.empty());
}

}  // namespace
