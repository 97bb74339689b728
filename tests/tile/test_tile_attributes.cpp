// vola tile keeps the attribute columns: every tile's columns equal vola::build's over
// the tile's points in file order (bit for bit), whatever the threads, chunking and
// memory budget; overviews reduce the finer voxels' values by each column's reduction
// (checked against a brute-force reduction written out here); inputs that do not share
// a column lose it with a warning.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <map>

#include "io_test_data.hpp"
#include "test_support.hpp"
#include "vola/io/las.hpp"
#include "vola/tile/tile_index.hpp"
#include "vola/tile/tiler.hpp"
#include "vola/vola.hpp"

namespace test_tile_attributes {
namespace {

namespace fs = std::filesystem;
using namespace vola;
using tile::TileIndex;

// Tiles of 512 ft at depth 5 (voxels of 0.5 ft: a power of two, so that the tiler's
// multiplication by the inverse and vola::build's quantization agree exactly).
tile::TileOptions autzen_grid(const fs::path& out) {
  tile::TileOptions o;
  o.grid.origin = {0.0, 0.0, 0.0};
  o.grid.tile_size = 512.0;
  o.grid.depth = 5;
  o.output_dir = out.string();
  o.threads = 2;
  o.memory_budget = std::uint64_t{1} << 20;  // 1 MiB: many spilled runs per tile
  o.overviews = false;
  return o;
}

// The whole file's points with the columns vola keeps from LAS, in file order.
PointCloud las_cloud(const fs::path& path) {
  io::LasReader reader(path.string());
  return io::las_points(reader, true, false);
}

std::map<std::string, std::vector<std::uint8_t>> tree_bytes(const fs::path& dir) {
  std::map<std::string, std::vector<std::uint8_t>> out;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    if (e.is_regular_file()) {
      std::ifstream in(e.path(), std::ios::binary);
      out[fs::relative(e.path(), dir).string()] = {std::istreambuf_iterator<char>(in), {}};
    }
  return out;
}

TEST(TileAttributes, EveryTileEqualsBuildOverItsPointsInFileOrder) {
  VOLA_REQUIRE_DATA(data);
  for (const fs::path& input : {data / "las" / "pdal_autzen_trim.las", data / "laz" / "pdal_autzen_trim.laz",
                               data / "las" / "pdal_extrabytes.las"}) {
    SCOPED_TRACE(input.string());
    vola_test::TempDir dir;
    tile::TileOptions o = autzen_grid(dir / "t");
    const auto source = tile::open_las_points(input.string(), 3000);
    auto comm = tile::single_process();
    const tile::TileSummary summary = tile::make_tiles({source.get()}, o, *comm);
    const PointCloud cloud = las_cloud(input);
    ASSERT_EQ(summary.attributes.size(), cloud.attributes.size());
    ASSERT_GT(summary.spill_runs, summary.tiles) << "the budget should force several runs per tile";

    // Each tile's points, in file order, built at once.
    const tile::Locator locator(o.grid);
    std::map<TileIndex, PointCloud> per_tile;
    for (std::size_t p = 0; p < cloud.size(); ++p) {
      TileIndex t;
      Key key;
      if (!locator.locate({cloud.xyz[3 * p], cloud.xyz[3 * p + 1], cloud.xyz[3 * p + 2]}, t, key)) continue;
      PointCloud& c = per_tile[t];
      if (c.attributes.empty())
        for (const auto& a : cloud.attributes) c.attributes.push_back({a.name, a.type, a.reduction, {}});
      c.xyz.insert(c.xyz.end(), cloud.xyz.begin() + static_cast<std::ptrdiff_t>(3 * p),
                   cloud.xyz.begin() + static_cast<std::ptrdiff_t>(3 * p + 3));
      for (std::size_t a = 0; a < cloud.attributes.size(); ++a) c.attributes[a].values.push_back(cloud.attributes[a].values[p]);
    }
    const tile::TileIndexFile index = tile::read_tile_index((dir / "t" / "index.geojson").string());
    ASSERT_EQ(index.tiles.size(), per_tile.size());
    for (const tile::TileEntry& e : index.tiles) {
      const Tree got = read((dir / "t" / e.file).string());
      BuildOptions build;
      build.quantization = Quantization::grid;
      build.voxel_size = o.grid.voxel_size();
      build.depth = o.grid.depth;
      build.origin = o.grid.tile_box(e.tile).min;
      const Tree want = vola::build(per_tile.at(e.tile), build);
      ASSERT_EQ(got.voxel_count(), want.voxel_count()) << e.file;
      ASSERT_EQ(got.attributes().size(), want.attributes().size()) << e.file;
      for (std::size_t c = 0; c < want.attributes().size(); ++c) {
        const AttributeColumn& g = got.attributes().columns()[c];
        const AttributeColumn& w = want.attributes().columns()[c];
        EXPECT_EQ(g.name(), w.name());
        EXPECT_TRUE(std::equal(g.bytes().begin(), g.bytes().end(), w.bytes().begin(), w.bytes().end()))
            << e.file << " column " << w.name();
      }
    }
  }
}

TEST(TileAttributes, SameBytesForAnyThreadsChunkingAndBudget) {
  VOLA_REQUIRE_DATA(data);
  const fs::path las = data / "las" / "pdal_autzen_trim.las";
  vola_test::TempDir dir;
  auto comm = tile::single_process();
  tile::TileOptions a = autzen_grid(dir / "a");
  a.threads = 1;
  a.memory_budget = std::uint64_t{1} << 30;
  a.overviews = true;
  const auto whole = tile::open_las_points(las.string(), std::size_t{1} << 20);
  tile::make_tiles({whole.get()}, a, *comm);
  tile::TileOptions b = autzen_grid(dir / "b");
  b.threads = 3;
  b.overviews = true;
  const auto small = tile::open_las_points(las.string(), 777);
  tile::make_tiles({small.get()}, b, *comm);
  const auto first = tree_bytes(dir / "a"), second = tree_bytes(dir / "b");
  EXPECT_GT(first.size(), 10u);
  ASSERT_EQ(first.size(), second.size());
  for (const auto& [name, bytes] : first) {
    ASSERT_TRUE(second.count(name)) << name;
    EXPECT_TRUE(bytes == second.at(name)) << name << " differs";
  }
}

// One overview voxel's value from its finer voxels' (in children order, then rank order),
// written out per reduction.
double reduce_by_hand(Reduction r, const std::vector<double>& v) {
  switch (r) {
    case Reduction::mean: {
      double sum = 0.0;
      for (const double x : v) sum += x;
      return sum / static_cast<double>(v.size());
    }
    case Reduction::max: return *std::max_element(v.begin(), v.end());
    case Reduction::min: return *std::min_element(v.begin(), v.end());
    case Reduction::last: return v.back();
    case Reduction::majority: {
      std::map<double, int> counts;  // ordered: ties go to the smallest value
      for (const double x : v) ++counts[x];
      double best = 0.0;
      int most = 0;
      for (const auto& [value, n] : counts)
        if (n > most) best = value, most = n;
      return best;
    }
  }
  return 0.0;
}

TEST(TileAttributes, OverviewsReduceTheFinerVoxels) {
  VOLA_REQUIRE_DATA(data);
  const fs::path las = data / "las" / "pdal_autzen_trim.las";
  vola_test::TempDir dir;
  tile::TileOptions o = autzen_grid(dir / "t");
  o.grid.tile_size = 32.0;  // depth 2: voxels of 2 ft, tiles of 32 ft; levels 1 has 4x4x4 tiles each
  o.grid.depth = 2;
  o.overviews = true;
  const auto source = tile::open_las_points(las.string(), 5000);
  auto comm = tile::single_process();
  tile::make_tiles({source.get()}, o, *comm);
  const tile::TileIndexFile index = tile::read_tile_index((dir / "t" / "index.geojson").string());
  ASSERT_FALSE(index.overviews.empty());
  // Level 0 (the tiles) by index; then each overview of level 1 against its children.
  std::map<TileIndex, std::string> level0;
  for (const tile::TileEntry& e : index.tiles) level0[e.tile] = e.file;
  std::size_t checked = 0;
  for (const tile::OverviewEntry& e : index.overviews) {
    if (e.level != 1) continue;
    const Tree parent = read((dir / "t" / e.file).string());
    ASSERT_FALSE(parent.attributes().empty()) << e.file;
    // parent voxel rank -> its finer voxels' values, per column
    std::map<std::uint64_t, std::vector<std::vector<double>>> finer;
    for (const auto& [t, file] : level0) {
      if (t.i >> 2 != e.tile.i || t.j >> 2 != e.tile.j || t.k >> 2 != e.tile.k) continue;
      const Tree child = read((dir / "t" / file).string());
      std::uint64_t rank = 0;
      child.for_each_voxel([&](const Voxel& v) {
        const std::uint32_t span = side_of(o.grid.depth - 1);
        const Voxel up{(t.i - 4 * e.tile.i) * span + v.x / 4, (t.j - 4 * e.tile.j) * span + v.y / 4,
                       (t.k - 4 * e.tile.k) * span + v.z / 4};
        auto& values = finer[*parent.rank(up)];
        values.resize(child.attributes().size());
        for (std::size_t c = 0; c < child.attributes().size(); ++c) values[c].push_back(child.attributes().columns()[c].get(rank));
        ++rank;
      });
    }
    ASSERT_EQ(finer.size(), parent.voxel_count()) << e.file;
    for (const auto& [rank, values] : finer)
      for (std::size_t c = 0; c < values.size(); ++c) {
        const AttributeColumn& column = parent.attributes().columns()[c];
        AttributeColumn expected(column.name(), column.type(), column.reduction(), 1);
        expected.set(0, reduce_by_hand(column.reduction(), values[c]));
        ASSERT_EQ(column.get(rank), expected.get(0)) << e.file << " " << column.name() << " voxel " << rank;
      }
    ++checked;
  }
  EXPECT_GT(checked, 0u);
}

TEST(TileAttributes, ColumnsNotEveryInputHasAreLeftOutWithAWarning) {
  VOLA_REQUIRE_DATA(data);
  vola_test::TempDir dir;
  tile::TileOptions o = autzen_grid(dir / "t");
  o.grid.tile_size = 4096.0;
  o.grid.depth = 3;
  const auto colour = tile::open_las_points((data / "las" / "pdal_autzen_trim.las").string());
  const auto plain = tile::open_las_points((data / "las" / "pdal_autzen_pf1.las").string());
  auto comm = tile::single_process();
  const tile::TileSummary s = tile::make_tiles({colour.get(), plain.get()}, o, *comm);
  EXPECT_EQ(s.attributes, (std::vector<std::string>{"intensity", "classification", "height", "number_of_returns"}));
  std::vector<std::string> left_out;  // the 1 MiB budget adds a warning of the largest tile
  for (const std::string& w : s.warnings)
    if (w.find("is left out") != std::string::npos) left_out.push_back(w);
  ASSERT_EQ(left_out.size(), 3u);  // red, green, blue
  EXPECT_NE(left_out[0].find("'red'"), std::string::npos) << left_out[0];
  EXPECT_NE(left_out[0].find("pdal_autzen_pf1.las has no such column"), std::string::npos) << left_out[0];
  // Without attributes: occupancy only, nothing to warn about.
  tile::TileOptions bare = autzen_grid(dir / "bare");
  bare.attributes = false;
  const tile::TileSummary none = tile::make_tiles({colour.get()}, bare, *comm);
  EXPECT_TRUE(none.attributes.empty());
  const tile::TileIndexFile index = tile::read_tile_index((dir / "bare" / "index.geojson").string());
  EXPECT_TRUE(read((dir / "bare" / index.tiles.front().file).string()).attributes().empty());
}

// Tiles of a reprojected survey: heights move with the points (feet to metres), so each
// voxel's mean height lies in the voxel's own vertical extent.
TEST(TileAttributes, ReprojectedHeightsAreInTheTargetsUnits) {
  VOLA_REQUIRE_DATA(data);
  vola_test::TempDir dir;
  tile::TileOptions o = autzen_grid(dir / "t");
  o.grid.tile_size = 256.0;  // metres now
  o.grid.depth = 5;          // voxels of 0.25 m
  auto las = tile::open_las_points((data / "las" / "pdal_autzen_trim.las").string(), 5000);
  const std::string from = las->wkt;
  const auto source = tile::reprojected(std::move(las), from, "EPSG:32610");
  auto comm = tile::single_process();
  tile::make_tiles({source.get()}, o, *comm);
  const tile::TileIndexFile index = tile::read_tile_index((dir / "t" / "index.geojson").string());
  std::uint64_t voxels = 0, outside = 0;
  for (const tile::TileEntry& e : index.tiles) {
    const Tree tree = read((dir / "t" / e.file).string());
    const AttributeColumn* height = tree.attributes().find("height");
    ASSERT_NE(height, nullptr) << e.file;
    std::uint64_t rank = 0;
    tree.for_each_voxel([&](const Voxel& v) {
      const double bottom = tree.frame().origin[2] + v.z * tree.frame().voxel_size;
      const double h = height->get(rank++);
      if (!(h >= bottom - 1e-3 && h <= bottom + tree.frame().voxel_size + 1e-3)) ++outside;
    });
    voxels += tree.voxel_count();
  }
  EXPECT_GT(voxels, 0u);
  EXPECT_EQ(outside, 0u) << "of " << voxels << " voxels";
}

// A LAS file cut after the source opened it: reading its chunks is an IoError naming
// the file (the records are read, not mapped: never SIGBUS).
TEST(TileSources, ALasFileCutWhileTiledIsAnError) {
  VOLA_REQUIRE_DATA(data);
  vola_test::TempDir dir;
  const fs::path copy = dir / "cut.las";
  fs::copy_file(data / "las" / "pdal_autzen_trim.las", copy);
  const auto source = tile::open_las_points(copy.string(), 4096);
  fs::resize_file(copy, fs::file_size(copy) / 2);
  std::vector<double> xyz;
  std::vector<std::vector<double>> values;
  bool failed = false;
  for (std::uint64_t c = 0; c < source->chunk_count(); ++c) {
    try {
      if (c % 2) source->read_chunk(c, xyz);
      else source->read_chunk_with_values(c, xyz, values);
    } catch (const IoError& e) {
      EXPECT_NE(std::string(e.what()).find("cut.las"), std::string::npos) << e.what();
      failed = true;
      break;
    }
  }
  EXPECT_TRUE(failed) << "reading past the cut succeeded";
}

}  // namespace
}  // namespace test_tile_attributes
