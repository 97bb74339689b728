// vola tile's parallel stages (bucketing, spilling, building, overviews, rendering) run
// on vola::parallel_for: an error thrown on a worker thread reaches make_tiles' or
// render's caller as that same vola::Error, and the other workers stop taking work.
#include <gtest/gtest.h>

#include <atomic>
#include <filesystem>
#include <random>

#include "parallel_fault.hpp"
#include "test_support.hpp"
#include "vola/error.hpp"
#include "vola/tile/tile_set.hpp"
#include "vola/tile/tiler.hpp"

namespace {

namespace fs = std::filesystem;
using namespace vola;

// `chunks` chunks of random points over a few tiles; chunk `failing` (if any) throws a
// FormatError instead, as a reader does on a damaged file. Counts the chunks read.
class ChunkedPoints final : public tile::PointSource {
 public:
  ChunkedPoints(std::uint64_t chunks, std::uint64_t points_per_chunk, std::optional<std::uint64_t> failing = {})
      : chunks_(chunks), per_chunk_(points_per_chunk), failing_(failing) {}
  const std::string& name() const noexcept override { return name_; }
  std::uint64_t chunk_count() const noexcept override { return chunks_; }
  std::uint64_t point_count() const noexcept override { return chunks_ * per_chunk_; }
  void read_chunk(std::uint64_t c, std::vector<double>& xyz) const override {
    ++reads;
    if (failing_ && c == *failing_) throw FormatError("points.las", 227 + c * 4096, "point record is truncated");
    std::mt19937_64 rng(c);
    std::uniform_real_distribution<double> u(-40.0, 70.0);
    xyz.clear();
    for (std::uint64_t i = 0; i < 3 * per_chunk_; ++i) xyz.push_back(u(rng));
  }
  mutable std::atomic<std::uint64_t> reads{0};

 private:
  std::uint64_t chunks_, per_chunk_;
  std::optional<std::uint64_t> failing_;
  std::string name_ = "chunked points";
};

tile::TileOptions options(const fs::path& out) {
  tile::TileOptions o;
  o.grid.origin = {-8.0, 0.0, -16.0};
  o.grid.tile_size = 32.0;
  o.grid.depth = 2;  // 16 voxels of 2 per tile edge: 4 x 3 x 4 tiles, two overview levels
  o.output_dir = out.string();
  o.threads = 2;
  o.memory_budget = std::uint64_t{1} << 20;
  return o;
}

// A small view of the test survey's tiles.
raycast::PinholeCamera small_camera() {
  raycast::PinholeCamera camera;
  camera.eye = {-60.0, -50.0, 90.0};
  camera.look_at = {15.0, 15.0, 15.0};
  camera.width = 48;
  camera.height = 32;
  return camera;
}

TEST(TileParallel, AWorkerErrorInEveryStageReachesTheCaller) {
  const ChunkedPoints points(8, 5000);
  for (const char* stage : {"tile.bucket", "tile.flush", "tile.build", "tile.overviews"}) {
    vola_test::TempDir dir;
    auto comm = tile::single_process();
    vola_test::expect_worker_error_reaches_caller(stage, [&] { tile::make_tiles({&points}, options(dir / "t"), *comm); });
    EXPECT_FALSE(fs::exists(dir / "t" / ".spill" / "rank-0")) << stage << ": spill files are removed after an error";
  }
  // Without a fault the same run succeeds (the hook is gone).
  vola_test::TempDir dir;
  auto comm = tile::single_process();
  const tile::TileSummary s = tile::make_tiles({&points}, options(dir / "t"), *comm);
  EXPECT_GT(s.tiles, 2u);
  EXPECT_GT(s.overview_files, 1u);

  const tile::TileSet tiles((dir / "t" / "index.geojson").string());
  const raycast::PinholeCamera camera = small_camera();
  vola_test::expect_worker_error_reaches_caller("tile.render", [&] { tile::render(tiles, camera, 2); });
  EXPECT_GT(tile::render(tiles, camera, 2).hits, 100u);
}

TEST(TileParallel, AReaderErrorStopsBucketingAndReachesTheCaller) {
  vola_test::TempDir dir;
  const ChunkedPoints points(400, 2000, 3);
  auto comm = tile::single_process();
  try {
    tile::make_tiles({&points}, options(dir / "t"), *comm);
    ADD_FAILURE() << "no exception";
  } catch (const FormatError& e) {
    EXPECT_EQ(e.file(), "points.las");
    EXPECT_EQ(e.offset(), std::optional<std::uint64_t>(227 + 3 * 4096));
    EXPECT_STREQ(e.what(), "points.las: byte 12515: point record is truncated");
  }
  // The workers stop taking chunks once one has failed (without that, the others would
  // read all 400).
  EXPECT_LT(points.reads.load(), 100u) << points.reads.load() << " chunks read";
  EXPECT_FALSE(fs::exists(dir / "t" / "index.geojson"));
}

TEST(TileParallel, AMissingTileFailsTheRenderWithItsError) {
  vola_test::TempDir dir;
  const ChunkedPoints points(4, 5000);
  auto comm = tile::single_process();
  tile::TileOptions o = options(dir / "t");
  o.overviews = false;
  tile::make_tiles({&points}, o, *comm);
  const tile::TileIndexFile index = tile::read_tile_index((dir / "t" / "index.geojson").string());
  for (const tile::TileEntry& e : index.tiles) fs::remove(dir / "t" / e.file);  // every tile gone
  const tile::TileSet tiles((dir / "t" / "index.geojson").string());
  const raycast::PinholeCamera camera = small_camera();
  try {
    tile::render(tiles, camera, 2);
    ADD_FAILURE() << "no exception";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(".vol"), std::string::npos) << e.what();
  }
}

}  // namespace
