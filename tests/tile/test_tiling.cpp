// vola tile against slow models: every tile holds exactly the voxels of its points
// (floor division written out here), the bytes do not depend on threads or the memory
// budget, overviews are the coarser cells, and tile-set queries (locate, mosaic, rays)
// agree with one grid over the same voxels.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <cmath>
#include <fstream>
#include <functional>
#include <map>
#include <random>
#include <set>

#include "io_test_data.hpp"
#include "test_support.hpp"
#include "vola/io/las.hpp"
#include "vola/raycast/ray_caster.hpp"
#include "vola/raycast/world.hpp"
#include "vola/tile/tile_set.hpp"
#include "vola/tile/tiler.hpp"

namespace {

namespace fs = std::filesystem;
using namespace vola;
using tile::TileIndex;

using Global = std::array<std::int64_t, 3>;  // voxel index on the whole grid

// floor((p - origin) / voxel) per axis, for voxel sizes that are powers of two (so that
// division and the library's multiplication by the inverse give the same double).
Global global_voxel(const Point& p, const tile::TileGrid& g) {
  Global out{};
  for (int a = 0; a < 3; ++a) out[a] = static_cast<std::int64_t>(std::floor((p[a] - g.origin[a]) / g.voxel_size()));
  return out;
}

std::int64_t floor_div(std::int64_t v, std::int64_t d) { return v >= 0 ? v / d : -((-v + d - 1) / d); }

// Points over several tiles either side of zero, a dense cluster, and non-finite ones.
class PointsInMemory final : public tile::PointSource {
 public:
  PointsInMemory(std::uint64_t n, std::uint64_t chunks, std::uint64_t seed) : chunks_(chunks) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> wide(-70.0, 90.0), tall(-10.0, 40.0), near(3.0, 9.0);
    for (std::uint64_t i = 0; i < n; ++i) {
      const bool cluster = i % 3 == 0;
      xyz_.push_back(cluster ? near(rng) : wide(rng));
      xyz_.push_back(cluster ? near(rng) : wide(rng));
      xyz_.push_back(cluster ? near(rng) : tall(rng));
    }
    xyz_.insert(xyz_.end(), {std::nan(""), 1.0, 1.0, 2.0, INFINITY, 2.0});
    name_ = "points in memory";
  }
  const std::string& name() const noexcept override { return name_; }
  std::uint64_t chunk_count() const noexcept override { return chunks_; }
  std::uint64_t point_count() const noexcept override { return xyz_.size() / 3; }
  void read_chunk(std::uint64_t c, std::vector<double>& xyz) const override {
    const std::uint64_t n = point_count(), first = n * c / chunks_, last = n * (c + 1) / chunks_;
    xyz.assign(xyz_.begin() + 3 * first, xyz_.begin() + 3 * last);
  }
  const std::vector<double>& all() const { return xyz_; }

 private:
  std::uint64_t chunks_;
  std::vector<double> xyz_;
  std::string name_;
};

tile::TileOptions small_grid(const fs::path& out) {
  tile::TileOptions o;
  o.grid.origin = {-8.0, 0.0, -16.0};
  o.grid.tile_size = 32.0;  // depth 3: 64 voxels of 0.5 per tile edge
  o.grid.depth = 3;
  o.output_dir = out.string();
  o.threads = 2;
  o.memory_budget = std::uint64_t{1} << 20;  // 1 MiB: the buffers spill many runs
  return o;
}

// Tile -> its voxels, from the points by floor division.
std::map<TileIndex, std::set<vola_test::Xyz>> expected_tiles(const std::vector<double>& xyz, const tile::TileGrid& g) {
  std::map<TileIndex, std::set<vola_test::Xyz>> out;
  const std::int64_t side = side_of(g.depth);
  for (std::size_t p = 0; p + 2 < xyz.size(); p += 3) {
    const Point point{xyz[p], xyz[p + 1], xyz[p + 2]};
    if (!std::isfinite(point[0]) || !std::isfinite(point[1]) || !std::isfinite(point[2])) continue;
    const Global v = global_voxel(point, g);
    const TileIndex t{static_cast<std::int32_t>(floor_div(v[0], side)), static_cast<std::int32_t>(floor_div(v[1], side)),
                      static_cast<std::int32_t>(floor_div(v[2], side))};
    out[t].insert({static_cast<std::uint32_t>(v[0] - t.i * side), static_cast<std::uint32_t>(v[1] - t.j * side),
                   static_cast<std::uint32_t>(v[2] - t.k * side)});
  }
  return out;
}

std::set<vola_test::Xyz> voxels_of(const Tree& tree) {
  std::set<vola_test::Xyz> out;
  tree.for_each_voxel([&](const Voxel& v) { out.insert({v.x, v.y, v.z}); });
  return out;
}

std::vector<std::uint8_t> bytes_of(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}

// Every file below `dir` (relative path -> bytes).
std::map<std::string, std::vector<std::uint8_t>> tree_bytes(const fs::path& dir) {
  std::map<std::string, std::vector<std::uint8_t>> out;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    if (e.is_regular_file()) out[fs::relative(e.path(), dir).string()] = bytes_of(e.path());
  return out;
}

TEST(TileGrid, LocateIsFloorDivisionOfTheGlobalVoxel) {
  tile::TileGrid g;
  g.origin = {-8.0, 0.0, -16.0};
  g.tile_size = 32.0;
  g.depth = 3;
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(-200.0, 200.0);
  for (int i = 0; i < 100000; ++i) {
    const Point p{u(rng), u(rng), i % 10 == 0 ? std::floor(u(rng)) : u(rng)};  // whole numbers: voxel faces
    TileIndex t;
    Key key;
    ASSERT_TRUE(g.locate(p, t, key));
    const Global v = global_voxel(p, g);
    EXPECT_EQ(t.i, floor_div(v[0], 64));
    EXPECT_EQ(t.k, floor_div(v[2], 64));
    const Voxel local = decode(key);
    EXPECT_EQ(static_cast<std::int64_t>(local.y), v[1] - 64 * floor_div(v[1], 64));
  }
  TileIndex t;
  Key key;
  EXPECT_FALSE(g.locate({std::nan(""), 0, 0}, t, key));
  EXPECT_FALSE(g.locate({1e300, 0, 0}, t, key));
  EXPECT_EQ(tile::tile_file_name({3, -2, 0}), "tile_3_-2_0.vol");
  g.tile_size = -1;
  EXPECT_THROW(g.check(), InvalidArgument);
}

TEST(Tiler, EveryTileHoldsExactlyItsPointsVoxels) {
  vola_test::TempDir dir;
  const PointsInMemory points(200000, 7, 1);
  const tile::TileOptions o = small_grid(dir / "tiles");
  auto comm = tile::single_process();
  const tile::TileSummary s = tile::make_tiles({&points}, o, *comm);
  EXPECT_GT(s.spill_runs, 20u);  // the budget forced spilling
  EXPECT_EQ(s.points_in, points.point_count());
  EXPECT_EQ(s.points_outside, 2u);

  const auto expected = expected_tiles(points.all(), o.grid);
  const tile::TileIndexFile index = tile::read_tile_index((dir / "tiles" / "index.geojson").string());
  ASSERT_EQ(index.tiles.size(), expected.size());
  std::uint64_t voxels = 0;
  for (const tile::TileEntry& e : index.tiles) {
    ASSERT_TRUE(expected.count(e.tile)) << e.file;
    const Tree tree = read((dir / "tiles" / e.file).string());
    EXPECT_EQ(voxels_of(tree), expected.at(e.tile)) << e.file;
    EXPECT_EQ(tree.voxel_count(), e.voxels);
    EXPECT_EQ(tree.frame(), o.grid.tile_frame(e.tile));
    for (int a = 0; a < 3; ++a) {  // the points' bbox lies inside the tile
      EXPECT_GE(e.bbox.min[a], o.grid.tile_box(e.tile).min[a]);
      EXPECT_LT(e.bbox.max[a], o.grid.tile_box(e.tile).max[a]);
    }
    voxels += e.voxels;
  }
  EXPECT_EQ(voxels, s.voxels);
  EXPECT_FALSE(fs::exists(dir / "tiles" / ".spill" / "rank-0")) << "spill files are removed";
}

// An output that names a file was a bare "filesystem error: cannot create directories".
TEST(Tiler, AnOutputThatIsAFileIsRefusedNamingIt) {
  vola_test::TempDir dir;
  const PointsInMemory points(100, 7, 1);
  const fs::path file = dir / "tiles";
  std::ofstream(file) << "not a folder";
  auto comm = tile::single_process();
  try {
    tile::make_tiles({&points}, small_grid(file), *comm);
    ADD_FAILURE() << "tiled into a file";
  } catch (const OptionError& e) {
    EXPECT_EQ(e.option(), "output_dir");
    EXPECT_NE(e.cause().find(file.string() + " is a file, not a folder"), std::string::npos) << e.cause();
  }
}

TEST(Tiler, SameBytesForAnyThreadCountChunkingAndBudget) {
  vola_test::TempDir dir;
  auto comm = tile::single_process();
  const PointsInMemory by7(120000, 7, 2), by1(120000, 1, 2);
  tile::TileOptions a = small_grid(dir / "a");
  a.threads = 1;
  a.memory_budget = std::uint64_t{1} << 30;
  tile::make_tiles({&by1}, a, *comm);
  tile::TileOptions b = small_grid(dir / "b");
  b.threads = 3;
  tile::make_tiles({&by7}, b, *comm);
  const auto first = tree_bytes(dir / "a"), second = tree_bytes(dir / "b");
  EXPECT_GT(first.size(), 10u);
  ASSERT_EQ(first.size(), second.size());
  for (const auto& [name, bytes] : first) {
    ASSERT_TRUE(second.count(name)) << name;
    EXPECT_TRUE(bytes == second.at(name)) << name << " differs";
  }
}

TEST(Tiler, OverviewsHoldTheCoarserCellsOfEveryTile) {
  vola_test::TempDir dir;
  const PointsInMemory points(60000, 3, 3);
  tile::TileOptions o = small_grid(dir / "t");
  o.grid.depth = 2;  // 16 voxels of 2 per tile: two overview levels over the 6 x 6 tiles
  auto comm = tile::single_process();
  tile::make_tiles({&points}, o, *comm);
  const tile::TileIndexFile index = tile::read_tile_index((dir / "t" / "index.geojson").string());
  ASSERT_FALSE(index.overviews.empty());
  std::map<int, std::map<TileIndex, std::set<vola_test::Xyz>>> expected;
  const std::int64_t side = side_of(o.grid.depth);
  for (std::size_t p = 0; p + 2 < points.all().size(); p += 3) {
    const Point point{points.all()[p], points.all()[p + 1], points.all()[p + 2]};
    if (!std::isfinite(point[0]) || !std::isfinite(point[1]) || !std::isfinite(point[2])) continue;
    const Global v = global_voxel(point, o.grid);
    for (int level = 1; level < o.grid.depth; ++level) {
      const std::int64_t scale = std::int64_t{1} << (2 * level);
      Global c{floor_div(v[0], scale), floor_div(v[1], scale), floor_div(v[2], scale)};
      const TileIndex t{static_cast<std::int32_t>(floor_div(c[0], side)), static_cast<std::int32_t>(floor_div(c[1], side)),
                        static_cast<std::int32_t>(floor_div(c[2], side))};
      expected[level][t].insert({static_cast<std::uint32_t>(c[0] - t.i * side),
                                 static_cast<std::uint32_t>(c[1] - t.j * side),
                                 static_cast<std::uint32_t>(c[2] - t.k * side)});
    }
  }
  std::size_t seen = 0;
  for (const tile::OverviewEntry& e : index.overviews) {
    const Tree tree = read((dir / "t" / e.file).string());
    EXPECT_EQ(voxels_of(tree), expected[e.level][e.tile]) << e.file;
    EXPECT_DOUBLE_EQ(tree.frame().voxel_size, o.grid.voxel_size() * std::pow(4.0, e.level));
    ++seen;
  }
  std::size_t wanted = 0;
  for (const auto& [level, tiles] : expected) wanted += tiles.size();
  EXPECT_EQ(seen, wanted);
}

TEST(TileSet, LocateMosaicAndRaysAgreeWithOneGrid) {
  vola_test::TempDir dir;
  const PointsInMemory points(40000, 4, 4);
  const tile::TileOptions o = small_grid(dir / "t");
  auto comm = tile::single_process();
  tile::make_tiles({&points}, o, *comm);
  const tile::TileSet tiles((dir / "t" / "index.geojson").string());
  EXPECT_EQ(tiles.tiles_opened(), 0u) << "opening the index maps no tile";

  // Every point's voxel is occupied; a point in an empty spot of a tile is not.
  for (std::size_t p = 0; p < 3000; ++p) {
    const Point point{points.all()[3 * p], points.all()[3 * p + 1], points.all()[3 * p + 2]};
    const tile::TileLookup found = tiles.locate(point);
    ASSERT_TRUE(found.in_tile && found.rank.has_value());
  }
  const tile::TileLookup far = tiles.locate({1e6, 1e6, 1e6});
  EXPECT_FALSE(far.in_tile);

  // One query near the origin opens only the tiles it needs.
  const tile::TileSet lazy((dir / "t" / "index.geojson").string());
  ASSERT_TRUE(lazy.locate({5.0, 5.0, 5.0}).rank.has_value());
  EXPECT_EQ(lazy.tiles_opened(), 1u);

  // The mosaic over everything holds every voxel, placed by the global index.
  const Tree mosaic = tiles.mosaic(tiles.bounds());
  std::set<vola_test::Xyz> expected;
  const Point corner = mosaic.frame().origin;
  for (std::size_t p = 0; p + 2 < points.all().size(); p += 3) {
    const Point point{points.all()[p], points.all()[p + 1], points.all()[p + 2]};
    if (!std::isfinite(point[0]) || !std::isfinite(point[1]) || !std::isfinite(point[2])) continue;
    const Global v = global_voxel(point, o.grid);
    Global c{};
    for (int a = 0; a < 3; ++a) c[a] = v[a] - static_cast<std::int64_t>(std::llround((corner[a] - o.grid.origin[a]) / o.grid.voxel_size()));
    expected.insert({static_cast<std::uint32_t>(c[0]), static_cast<std::uint32_t>(c[1]), static_cast<std::uint32_t>(c[2])});
  }
  EXPECT_EQ(voxels_of(mosaic), expected);

  // Rays: the tile set and a caster over the mosaic find the same voxel at the same distance.
  const raycast::RayCaster one(mosaic);
  std::mt19937_64 rng(9);
  std::uniform_real_distribution<double> u(-120.0, 140.0), dir_u(-1.0, 1.0);
  int hits = 0;
  for (int r = 0; r < 20000; ++r) {
    raycast::Ray ray;
    ray.origin = {u(rng), u(rng), u(rng)};
    Point d{dir_u(rng), dir_u(rng), dir_u(rng)};
    const double n = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    if (n < 1e-3) continue;
    if (r % 10 == 0) {
      d = {0, 0, -1};  // straight down, along an axis
    } else if (r % 2) {  // at a point of the cloud: mostly hits, often through other tiles first
      const std::size_t p = static_cast<std::size_t>(r) * 7919 % 40000;
      for (int a = 0; a < 3; ++a) d[a] = points.all()[3 * p + a] - ray.origin[a];
      const double m = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
      for (double& c : d) c /= m;
    } else {
      for (double& c : d) c /= n;
    }
    ray.direction = d;
    const auto a = tiles.cast(ray);
    const auto b = one.cast(raycast::world_ray_to_grid(mosaic.frame(), ray));
    ASSERT_EQ(a.has_value(), b.has_value()) << "ray " << r;
    if (!a) continue;
    ++hits;
    const Point world_a = o.grid.tile_origin(a->tile);
    for (int ax = 0; ax < 3; ++ax) {
      const std::uint32_t va = ax == 0 ? a->voxel.x : (ax == 1 ? a->voxel.y : a->voxel.z);
      const std::uint32_t vb = ax == 0 ? b->voxel.x : (ax == 1 ? b->voxel.y : b->voxel.z);
      EXPECT_DOUBLE_EQ(world_a[ax] + va * o.grid.voxel_size(), corner[ax] + vb * o.grid.voxel_size()) << "ray " << r;
    }
    EXPECT_NEAR(a->t, b->t * o.grid.voxel_size(), 1e-9) << "ray " << r;
    EXPECT_EQ(a->normal, b->normal) << "ray " << r;
  }
  EXPECT_GT(hits, 8000);
}

// A copy of the set's index with its features changed by `edit`, written as `name`.
std::string edited_index(const fs::path& folder, const std::string& name,
                         const std::function<void(nlohmann::json& features)>& edit) {
  nlohmann::json index = nlohmann::json::parse(std::ifstream(folder / "index.geojson"));
  edit(index["features"]);
  std::ofstream(folder / name) << index.dump();
  return (folder / name).string();
}

// Listed tiles far apart: the DDA steps through every empty cell between them (an index
// with one tile at [2^31 - 1, ...] spun for minutes), so such rays take the listed tiles
// in their order instead, with the same hits. A tile file is checked against the cell the
// index puts it in: a swapped index answered "empty" for occupied points.
TEST(TileSet, FarApartTilesAndMisplacedFiles) {
  vola_test::TempDir dir;
  const PointsInMemory points(40000, 4, 4);
  const tile::TileOptions o = small_grid(dir / "t");
  auto comm = tile::single_process();
  tile::make_tiles({&points}, o, *comm);
  const tile::TileSet near((dir / "t" / "index.geojson").string());
  ASSERT_GE(near.index().tiles.size(), 2u);
  const tile::TileSet spread(edited_index(dir / "t", "far.geojson", [](nlohmann::json& features) {
    nlohmann::json far = features[0];
    far["properties"]["tile"] = {2147483000, 2147483000, 2147483000};
    features.push_back(far);
  }));
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-120.0, 140.0);
  int hits = 0;
  for (int r = 0; r < 2000; ++r) {
    raycast::Ray ray;
    ray.origin = {u(rng), u(rng), u(rng)};
    const std::size_t p = static_cast<std::size_t>(r) * 7919 % 40000;
    Point d{};
    for (int a = 0; a < 3; ++a) d[a] = points.all()[3 * p + a] - ray.origin[a];
    const double m = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    if (!(m > 1e-3)) continue;
    for (double& c : d) c /= m;
    ray.direction = d;
    const auto a = near.cast(ray), b = spread.cast(ray);
    ASSERT_EQ(a.has_value(), b.has_value()) << "ray " << r;
    if (!a) continue;
    ++hits;
    EXPECT_EQ(a->tile, b->tile);
    EXPECT_EQ(a->voxel, b->voxel);
    EXPECT_EQ(a->t, b->t);
  }
  EXPECT_GT(hits, 1000);

  const tile::TileSet swapped(edited_index(dir / "t", "swapped.geojson", [](nlohmann::json& features) {
    std::swap(features[0]["properties"]["file"], features[1]["properties"]["file"]);
  }));
  const tile::TileIndex first = near.index().tiles[0].tile;
  const Box box = near.grid().tile_box(first);
  try {
    swapped.locate({0.5 * (box.min[0] + box.max[0]), 0.5 * (box.min[1] + box.max[1]), 0.5 * (box.min[2] + box.max[2])});
    ADD_FAILURE() << "a tile file in another tile's cell was read";
  } catch (const FormatError& e) {
    EXPECT_NE(std::string(e.what()).find("is not that of the cell"), std::string::npos) << e.what();
  }
}

TEST(TileIndex, BadIndexFilesGetClearErrors) {
  vola_test::TempDir dir;
  const auto write_text = [&](const std::string& name, const std::string& text) {
    std::ofstream(dir / name) << text;
    return (dir / name).string();
  };
  const auto message_of = [](const std::string& path) {
    try {
      tile::read_tile_index(path);
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message_of(write_text("a.geojson", "{\"type\": ")).find("not valid JSON"), std::string::npos);
  EXPECT_NE(message_of(write_text("b.geojson", "{\"type\": \"FeatureCollection\"}")).find("no \"vola\" member"),
            std::string::npos);
  const std::string head =
      "{\"vola\": {\"format\": \"vola-tile-index\", \"version\": 1, \"origin\": [0,0,0], \"tile_size\": 8, "
      "\"depth\": 2, \"epsg\": null}, \"features\": [";
  EXPECT_NE(message_of(write_text("c.geojson", head + "{\"properties\": {\"tile\": [1, 2], \"file\": \"x.vol\"}}]}"))
                .find("\"tile\" must be [i, j, k]"),
            std::string::npos);
  EXPECT_NE(message_of(write_text("d.geojson", head + "{\"properties\": {\"tile\": [1, 2, 3], \"file\": \"../x.vol\"}}]}"))
                .find("inside the index's folder"),
            std::string::npos);
  EXPECT_NE(message_of(write_text("e.geojson", head + "{\"properties\": {\"tile\": [1, 2, 3]}}]}")).find("missing"),
            std::string::npos);
  const std::string bad_depth = "{\"vola\": {\"format\": \"vola-tile-index\", \"version\": 1, \"origin\": [0,0,0], "
                                "\"tile_size\": 8, \"depth\": 12, \"epsg\": null}, \"features\": []}";
  EXPECT_NE(message_of(write_text("f.geojson", bad_depth)).find("bad grid"), std::string::npos);
  // A listed tile whose file is gone: the query that needs it says which file.
  const std::string missing = write_text("g.geojson", head + "{\"properties\": {\"tile\": [0, 0, 0], \"file\": \"gone.vol\"}}]}");
  const tile::TileSet tiles(missing);
  EXPECT_THROW(tiles.locate({1, 1, 1}), Error);
}

TEST(PointSource, LasChunksDecodeLikeTheReader) {
  VOLA_REQUIRE_GOLDEN(golden);
  const fs::path las = vola_io_test::data_dir() / "las" / "pdal_autzen_trim.las";
  const auto source = tile::open_las_points(las.string(), 4096);
  io::LasReader reader(las.string());
  io::LasChunk chunk;
  std::vector<double> xyz, expected;
  for (std::uint64_t c = 0; c < source->chunk_count(); ++c) {
    source->read_chunk(c, xyz);
    reader.read(chunk, 4096, true);
    ASSERT_EQ(xyz, chunk.xyz) << "chunk " << c;
  }
  EXPECT_EQ(reader.read(chunk, 4096, true), 0u);
  EXPECT_EQ(source->point_count(), reader.header().point_count);
  EXPECT_TRUE(source->epsg.has_value() || !source->wkt.empty());
}

}  // namespace

namespace {

// The index is outside bytes too: random byte flips, cuts and insertions of a real index
// must give a tile set or a vola::Error, never a crash or another exception.
TEST(TileIndex, MutatedIndexesFailCleanly) {
  vola_test::TempDir dir;
  const PointsInMemory points(3000, 1, 6);
  const tile::TileOptions o = small_grid(dir / "t");
  auto comm = tile::single_process();
  tile::make_tiles({&points}, o, *comm);
  const std::vector<std::uint8_t> original = bytes_of(dir / "t" / "index.geojson");
  std::mt19937_64 rng(11);
  const std::string alphabet = "{}[]\",:0123456789.-eE truefalsnul\\";
  int parsed = 0;
  for (int m = 0; m < 3000; ++m) {
    std::vector<std::uint8_t> bytes = original;
    const int edits = 1 + static_cast<int>(rng() % 4);
    for (int e = 0; e < edits && !bytes.empty(); ++e) {
      const std::size_t at = rng() % bytes.size();
      switch (rng() % 3) {
        case 0: bytes[at] = static_cast<std::uint8_t>(alphabet[rng() % alphabet.size()]); break;
        case 1: bytes.erase(bytes.begin() + static_cast<std::ptrdiff_t>(at)); break;
        default: bytes.resize(at); break;
      }
    }
    const fs::path path = dir / "t" / "mutated.geojson";
    vola_test::write_bytes(path, bytes);
    try {
      const tile::TileSet tiles(path.string());
      tiles.locate({5.0, 5.0, 5.0});
      ++parsed;
    } catch (const Error&) {
    } catch (const std::exception& e) {
      FAIL() << "mutation " << m << ": not a vola::Error: " << e.what();
    }
  }
  EXPECT_GT(parsed, 10) << "some mutations (inside numbers or names) still read";
}

}  // namespace
