// OpenVDB .vdb written by vola and read back by OpenVDB itself (active voxels, values and
// the transform's placement of every voxel centre); files written by OpenVDB in the test
// read by vola; transforms vola cannot represent and damaged files refused with an error.
#include <openvdb/io/File.h>
#include <openvdb/openvdb.h>

#include <cmath>

#include "map_test_support.hpp"
#include "vola/convert.hpp"
#include "vola/io/occupancy_maps.hpp"

namespace {

using vola_map_test::Cell;
using vola_map_test::cells_of;
using vola_map_test::random_map;
using vola_map_test::tree_of;

struct Grids {
  openvdb::GridPtrVecPtr grids;
  openvdb::GridBase::Ptr named(const std::string& name) const {
    for (const auto& g : *grids)
      if (g->getName() == name) return g;
    return nullptr;
  }
};

Grids read_with_openvdb(const vola_test::fs::path& path) {
  openvdb::initialize();
  openvdb::io::File file(path.string());
  file.open(false);
  Grids out{file.getGrids()};
  file.close();
  return out;
}

// Each active voxel of `grid` with its value, by the world cell its centre lies in.
template <class GridT>
std::map<Cell, typename GridT::ValueType> world_cells(const GridT& grid, double size) {
  std::map<Cell, typename GridT::ValueType> cells;
  const auto add = [&](const openvdb::Coord& ijk, const typename GridT::ValueType& value) {
    const openvdb::Vec3d centre = grid.transform().indexToWorld(ijk);
    Cell cell;
    for (int a = 0; a < 3; ++a) {
      cell[a] = static_cast<std::int64_t>(std::floor(centre[a] / size));
      // The centre, not only the cell: within rounding of the middle of the cell.
      EXPECT_NEAR(centre[a], (static_cast<double>(cell[a]) + 0.5) * size, 1e-9 * std::max(1.0, std::fabs(centre[a])));
    }
    cells[cell] = value;
  };
  for (auto it = grid.cbeginValueOn(); it; ++it) {
    openvdb::CoordBBox box;
    it.getBoundingBox(box);  // one voxel, or a pruned tile's voxels
    for (auto ijk = box.begin(); ijk; ++ijk) add(*ijk, *it);
  }
  return cells;
}

template <class Map>
std::set<Cell> keys_of(const Map& cells) {
  std::set<Cell> keys;
  for (const auto& entry : cells) keys.insert(entry.first);
  return keys;
}

TEST(VdbExport, BoolGridHoldsTheVoxelsAtTheirCentres) {
  vola_test::TempDir dir;
  for (std::uint64_t seed = 1; seed <= 6; ++seed) {
    const double size = seed % 2 ? 0.1 : 2.5;
    const auto map = random_map(seed, size, 3000, 2000);
    const vola::Tree tree = tree_of(map.occupied, size, false);
    const auto report = vola::io::write_vdb(vola::io::map_voxels(tree), (dir / "m.vdb").string());
    EXPECT_EQ(report.grids, std::vector<std::string>{"occupied"});
    const Grids read = read_with_openvdb(dir / "m.vdb");
    ASSERT_EQ(read.grids->size(), 1u);
    const auto grid = openvdb::gridPtrCast<openvdb::BoolGrid>(read.named("occupied"));
    ASSERT_TRUE(grid);
    EXPECT_DOUBLE_EQ(grid->voxelSize()[0], size);
    EXPECT_EQ(keys_of(world_cells(*grid, size)), keys_of(map.occupied)) << seed;
    // vola's own centre of each voxel maps back to the index OpenVDB stores it at.
    const vola::Quantizer quantizer = tree.quantizer();
    tree.for_each_voxel([&](const vola::Voxel& v) {
      const vola::Point c = quantizer.center(v);
      const openvdb::Coord ijk = grid->transform().worldToIndexCellCentered(openvdb::Vec3d(c[0], c[1], c[2]));
      EXPECT_TRUE(grid->tree().isValueOn(ijk));
    });
  }
}

TEST(VdbExport, LogOddsAndFreeVoxelsGoToFloatGrids) {
  vola_test::TempDir dir;
  const auto map = random_map(10, 0.2, 500, 5000);
  const vola::Tree occupied = tree_of(map.occupied, 0.2, true), free = tree_of(map.free, 0.2, true);
  const auto report = vola::io::write_vdb(vola::io::map_voxels(occupied, &free), (dir / "s.vdb").string());
  EXPECT_EQ(report.grids, (std::vector<std::string>{"log_odds", "free_log_odds"}));
  EXPECT_EQ(report.free, map.free.size());
  const Grids read = read_with_openvdb(dir / "s.vdb");
  const auto hits = openvdb::gridPtrCast<openvdb::FloatGrid>(read.named("log_odds"));
  const auto misses = openvdb::gridPtrCast<openvdb::FloatGrid>(read.named("free_log_odds"));
  ASSERT_TRUE(hits && misses);
  const auto hit_cells = world_cells(*hits, 0.2), miss_cells = world_cells(*misses, 0.2);
  EXPECT_EQ(hit_cells.size(), map.occupied.size());
  EXPECT_EQ(miss_cells.size(), map.free.size());
  for (const auto& [cell, value] : map.occupied) EXPECT_EQ(hit_cells.at(cell), value);
  for (const auto& [cell, value] : map.free) EXPECT_EQ(miss_cells.at(cell), value);
  // Read back without naming a grid: the occupied one, though "free_log_odds" sorts first.
  const vola::Tree back = vola::convert((dir / "s.vdb").string(), {});
  EXPECT_EQ(back.voxel_count(), map.occupied.size());
  ASSERT_TRUE(back.attributes().find("log_odds"));
}

// Voxels one per 128^3 block: each costs OpenVDB an internal node of 33 KiB, 4.7 GB in all.
TEST(VdbExport, ThinlyScatteredVoxelsAreRefusedBeforeOpenvdbBuildsThem) {
  vola_test::TempDir dir;
  vola::io::MapVoxels voxels;
  for (std::uint32_t i = 0; i < 60; ++i)
    for (std::uint32_t j = 0; j < 60; ++j)
      for (std::uint32_t k = 0; k < 40; ++k) voxels.occupied.push_back({128 * i, 128 * j, 128 * k});
  try {
    vola::io::write_vdb(voxels, (dir / "thin.vdb").string());
    ADD_FAILURE() << "a 4.7 GB OpenVDB tree was built";
  } catch (const vola::InvalidArgument& e) {
    EXPECT_NE(std::string(e.what()).find("OpenVDB would need about 4."), std::string::npos) << e.what();
  }
  EXPECT_FALSE(vola_test::fs::exists(dir / "thin.vdb"));
  voxels.occupied.resize(20000);  // 0.6 GB: written
  EXPECT_EQ(vola::io::write_vdb(voxels, (dir / "thin.vdb").string()).occupied, 20000u);
}

TEST(VdbImport, RoundTripGivesTheSameVoxelsValuesAndFrame) {
  vola_test::TempDir dir;
  for (std::uint64_t seed = 20; seed < 24; ++seed) {
    const auto map = random_map(seed, 0.05, 4000, 3000);
    const vola::Tree tree = tree_of(map.occupied, 0.05, true);
    vola::io::write_vdb(vola::io::map_voxels(tree), (dir / "r.vdb").string());
    const vola::Tree back = vola::convert((dir / "r.vdb").string(), {});
    EXPECT_EQ(back.frame().voxel_size, 0.05);
    EXPECT_EQ(back.frame().origin, tree.frame().origin) << seed;
    const auto cells = cells_of(back);
    ASSERT_EQ(keys_of(cells), keys_of(map.occupied));
    for (const auto& [cell, value] : map.occupied) EXPECT_EQ(cells.at(cell), value);
  }
}

// A file OpenVDB writes on its own: a float grid with a translated transform, scattered
// voxels and an active tile (a whole 8^3 leaf's worth at a coarser level), and a second grid.
TEST(VdbImport, AFileWrittenByOpenvdbReadsCellForCell) {
  openvdb::initialize();
  vola_test::TempDir dir;
  const double size = 0.3;
  auto density = openvdb::FloatGrid::create(0.0f);
  density->setName("density");
  density->setTransform(openvdb::math::Transform::createLinearTransform(size));
  density->transform().postTranslate(openvdb::Vec3d(10.0, -4.0, 2.5));
  std::map<openvdb::Coord, float> expected;
  std::mt19937_64 rng(7);
  for (int n = 0; n < 500; ++n) {
    const openvdb::Coord c(static_cast<int>(rng() % 200) - 100, static_cast<int>(rng() % 50), static_cast<int>(rng() % 30) - 60);
    const float value = static_cast<float>(rng() % 1000) / 7.0f;
    density->tree().setValueOn(c, value);
    expected[c] = value;
  }
  density->tree().addTile(1, openvdb::Coord(800, 800, 800), 2.0f, true);  // 8^3 voxels from (800, 800, 800)
  for (int x = 0; x < 8; ++x)
    for (int y = 0; y < 8; ++y)
      for (int z = 0; z < 8; ++z) expected[openvdb::Coord(800 + x, 800 + y, 800 + z)] = 2.0f;
  auto mask = openvdb::BoolGrid::create(false);
  mask->setName("mask");
  mask->tree().setValueOn(openvdb::Coord(1, 2, 3), true);
  openvdb::io::File((dir / "fields.vdb").string()).write({density, mask});

  vola::ConvertOptions options;
  // Two grids of its own: which one is wanted is the user's to say (OpenVDB lists grids by
  // name, so "the first" would be the first name, not the first written).
  try {
    vola::convert((dir / "fields.vdb").string(), options);
    ADD_FAILURE() << "one of two grids was picked";
  } catch (const vola::FormatError& e) {
    EXPECT_NE(std::string(e.what()).find("holds 2 grids ('density', 'mask'): choose one with --grid NAME"),
              std::string::npos)
        << e.what();
  }
  options.grid = "density";
  const vola::Tree tree = vola::convert((dir / "fields.vdb").string(), options);
  ASSERT_EQ(tree.voxel_count(), expected.size());
  EXPECT_DOUBLE_EQ(tree.frame().voxel_size, size);
  const vola::AttributeColumn* column = tree.attributes().find("density");
  ASSERT_TRUE(column);
  const vola::Quantizer quantizer = tree.quantizer();
  std::size_t rank = 0;
  tree.for_each_voxel([&](const vola::Voxel& v) {
    const vola::Point c = quantizer.center(v);
    const openvdb::Vec3d index = density->transform().worldToIndex(openvdb::Vec3d(c[0], c[1], c[2]));
    const openvdb::Coord ijk(static_cast<int>(std::lround(index[0])), static_cast<int>(std::lround(index[1])),
                             static_cast<int>(std::lround(index[2])));
    for (int a = 0; a < 3; ++a) EXPECT_NEAR(index[a], ijk[a], 1e-6);  // vola's centre is OpenVDB's index centre
    ASSERT_TRUE(expected.count(ijk));
    EXPECT_FLOAT_EQ(static_cast<float>(column->get(rank++)), expected.at(ijk));
  });

  options.grid = "mask";
  const vola::Tree mask_tree = vola::convert((dir / "fields.vdb").string(), options);
  EXPECT_EQ(mask_tree.voxel_count(), 1u);
  EXPECT_TRUE(mask_tree.attributes().empty());
  options.grid = "velocity";
  try {
    vola::convert((dir / "fields.vdb").string(), options);
    ADD_FAILURE() << "a missing grid was accepted";
  } catch (const vola::FormatError& e) {
    EXPECT_NE(std::string(e.what()).find("its grids: 'density', 'mask'"), std::string::npos) << e.what();
  }
}

TEST(VdbImport, TransformsVolaCannotHoldAreRefused) {
  openvdb::initialize();
  vola_test::TempDir dir;
  const auto refused = [&](openvdb::math::Transform::Ptr transform, const std::string& why) {
    auto grid = openvdb::BoolGrid::create(false);
    grid->setTransform(transform);
    grid->tree().setValueOn(openvdb::Coord(0, 0, 0), true);
    openvdb::io::File((dir / "t.vdb").string()).write({grid});
    try {
      vola::convert((dir / "t.vdb").string(), {});
      ADD_FAILURE() << why << " was accepted";
    } catch (const vola::FormatError& e) {
      EXPECT_NE(std::string(e.what()).find(why), std::string::npos) << e.what();
    }
  };
  auto rotated = openvdb::math::Transform::createLinearTransform(0.5);
  rotated->postRotate(0.3, openvdb::math::Z_AXIS);
  refused(rotated, "rotates, shears or scales the axes unequally");
  auto stretched = openvdb::math::Transform::createLinearTransform(openvdb::Mat4R(
      0.5, 0.0, 0.0, 0.0, 0.0, 0.5, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0));
  refused(stretched, "rotates, shears or scales the axes unequally");
  refused(openvdb::math::Transform::createFrustumTransform(openvdb::BBoxd(openvdb::Vec3d(0), openvdb::Vec3d(10)), 0.5, 1.0),
          "not linear");
}

TEST(VdbImport, OtherVoxelSizesAreRefused) {
  vola_test::TempDir dir;
  vola::io::MapVoxels voxels;
  voxels.frame.voxel_size = 0.4;
  voxels.occupied = {{0, 0, 0}};
  vola::io::write_vdb(voxels, (dir / "m.vdb").string());
  vola::ConvertOptions options;
  options.voxel_size = 0.2;
  EXPECT_THROW(vola::convert((dir / "m.vdb").string(), options), vola::OptionError);
}

TEST(VdbImport, DamagedFilesAreErrors) {
  vola_test::TempDir dir;
  const auto map = random_map(30, 0.1, 300, 3000);
  vola::io::write_vdb(vola::io::map_voxels(tree_of(map.occupied, 0.1, true)), (dir / "whole.vdb").string());
  const std::vector<std::uint8_t> bytes = vola_test::read_bytes(dir / "whole.vdb");
  for (std::size_t cut = 0; cut < bytes.size(); cut += std::max<std::size_t>(1, bytes.size() / 97)) {
    vola_test::write_bytes(dir / "cut.vdb", std::vector<std::uint8_t>(bytes.begin(), bytes.begin() + cut));
    EXPECT_THROW(vola::convert((dir / "cut.vdb").string(), {}), vola::Error) << "cut at " << cut;
  }
  std::vector<std::uint8_t> noise(4096);
  std::mt19937_64 rng(3);
  for (auto& b : noise) b = static_cast<std::uint8_t>(rng());
  vola_test::write_bytes(dir / "noise.vdb", noise);
  EXPECT_THROW(vola::convert((dir / "noise.vdb").string(), {}), vola::FormatError);
}

}  // namespace
