// binvox: the shared files against EXPECTED.txt, a slow dense decoder and the chair's
// OBJ bounds (which fix the axis order); write -> read round trips; header variants;
// truncated and corrupted input.
#include <gtest/gtest.h>

#include <random>

#include "io_test_data.hpp"
#include "memory_cap.hpp"
#include "vola/io/binvox.hpp"
#include "vola/io/input.hpp"

namespace {

using namespace vola_io_test;
using vola_test::Xyz;
using vola_test::XyzSet;

XyzSet voxel_set(const vola::io::VoxelGrid& grid) {
  XyzSet cells;
  for (const auto& v : grid.voxels) cells.insert(vola_test::to_xyz(v));
  return cells;
}

// Slow decoder of a cubic file: expand every run into a dense array of cells, then
// walk the array with the binvox index formula (y fastest, then z, then x).
XyzSet slow_decode(const Bytes& bytes, std::uint32_t side) {
  const std::string text(bytes.begin(), bytes.end());
  std::size_t at = text.find("\ndata\n") + 6;
  std::vector<bool> dense;
  for (; at + 1 < bytes.size(); at += 2) dense.insert(dense.end(), bytes[at + 1], bytes[at] == 1);
  EXPECT_EQ(dense.size(), std::size_t{side} * side * side);
  XyzSet cells;
  for (std::uint32_t x = 0; x < side; ++x)
    for (std::uint32_t z = 0; z < side; ++z)
      for (std::uint32_t y = 0; y < side; ++y)
        if (dense[(std::size_t{x} * side + z) * side + y]) cells.insert({x, y, z});
  return cells;
}

TEST(Binvox, SharedFilesMatchExpectedAndTheSlowDecoder) {
  VOLA_REQUIRE_DATA(data);
  const auto files = files_ending(data / "binvox", ".binvox");
  ASSERT_EQ(files.size(), 3u);
  for (const auto& path : files) {
    SCOPED_TRACE(path.string());
    const std::string line = expected_line(data, path.filename().string());
    const vola::io::Input in = vola::io::read_input(path.string(), "auto", {});
    EXPECT_EQ(in.format, "binvox");
    ASSERT_TRUE(in.grid);
    // EXPECTED.txt: "binvox dim 32 32 32 total=32768 occupied=N".
    EXPECT_EQ(in.grid->voxels.size(), expected_integer(line, "occupied=").value());
    const auto side = static_cast<std::uint32_t>(expected_integer(line, "binvox dim ").value());
    EXPECT_EQ(in.grid->dims, (std::array<std::uint32_t, 3>{side, side, side}));
    EXPECT_EQ(voxel_set(*in.grid), slow_decode(vola_test::read_bytes(path), side));
  }
}

TEST(Binvox, CommentedHeaderGivesTheSameChairInTheObjsPlace) {
  VOLA_REQUIRE_DATA(data);
  const auto clean = vola::io::read_binvox((data / "binvox" / "trimesh_chair_model.binvox").string());
  const auto commented = vola::io::read_binvox((data / "binvox" / "trimesh_chair_model_commented_header.binvox").string());
  EXPECT_EQ(voxel_set(clean), voxel_set(commented));
  EXPECT_EQ(clean.origin, commented.origin);
  EXPECT_EQ(clean.voxel_size, commented.voxel_size);
  // Header: translate -0.265511 -0.331878 -0.263364, scale 0.663756, dim 32.
  EXPECT_EQ(clean.origin, (vola::Point{-0.265511, -0.331878, -0.263364}));
  EXPECT_DOUBLE_EQ(clean.voxel_size, 0.663756 / 32);
  // The chair was voxelized from mesh/obj/trimesh_chair_model.obj; EXPECTED.txt gives
  // its bbox [-0.2655, -0.3319, -0.2634]..[0.2655, 0.3319, 0.2634]. The occupied cells
  // must span it on every axis (y, the longest, all 32 cells), which only the right
  // axis order achieves.
  const vola::Point obj_min{-0.2655, -0.3319, -0.2634}, obj_max{0.2655, 0.3319, 0.2634};
  std::array<std::uint32_t, 3> lo{~0u, ~0u, ~0u}, hi{0, 0, 0};
  for (const auto& v : clean.voxels) {
    const std::uint32_t c[3] = {v.x, v.y, v.z};
    for (std::size_t a = 0; a < 3; ++a) {
      lo[a] = std::min(lo[a], c[a]);
      hi[a] = std::max(hi[a], c[a]);
    }
  }
  for (std::size_t a = 0; a < 3; ++a) {
    const double world_min = clean.origin[a] + lo[a] * clean.voxel_size;
    const double world_max = clean.origin[a] + (hi[a] + 1) * clean.voxel_size;
    EXPECT_NEAR(world_min, obj_min[a], clean.voxel_size) << "axis " << a;
    EXPECT_NEAR(world_max, obj_max[a], clean.voxel_size) << "axis " << a;
  }
  EXPECT_EQ(hi[1] - lo[1] + 1, 32u);
}

vola::Tree random_tree(std::mt19937_64& rng, int depth, std::uint32_t side, std::size_t count) {
  std::vector<vola::Voxel> voxels;
  for (std::size_t i = 0; i < count; ++i)
    voxels.push_back({static_cast<std::uint32_t>(rng() % side), static_cast<std::uint32_t>(rng() % side),
                      static_cast<std::uint32_t>(rng() % side)});
  return vola::build_from_voxels(voxels, depth);
}

TEST(Binvox, WriteThenReadGivesTheSameVoxelsInTheSamePlace) {
  std::mt19937_64 rng(11);
  vola_test::TempDir dir;
  for (int round = 0; round < 40; ++round) {
    const int depth = 1 + round % 4;
    const std::uint32_t side = vola::side_of(depth) - static_cast<std::uint32_t>(rng() % 3);
    vola::Tree tree = random_tree(rng, depth, side, round % 10 == 0 ? 1 : 1 + rng() % 3000);
    vola::Frame frame;
    frame.quantization = vola::Quantization::grid;
    frame.origin = {-12.5 + round, 0.1 * round, 1e6};
    frame.voxel_size = 0.25 + 0.01 * round;
    tree.set_frame(frame);
    const auto path = dir / ("tree" + std::to_string(round) + ".binvox");
    vola::io::write_binvox(tree, path.string());
    const vola::io::VoxelGrid back = vola::io::read_binvox(path.string());
    SCOPED_TRACE(round);
    EXPECT_EQ(voxel_set(back), vola_test::voxel_set(tree));
    std::uint32_t largest = 0;
    for (const auto& v : back.voxels) largest = std::max({largest, v.x, v.y, v.z});
    EXPECT_EQ(back.dims, (std::array<std::uint32_t, 3>{largest + 1, largest + 1, largest + 1}));
    EXPECT_EQ(back.origin, frame.origin);
    EXPECT_NEAR(back.voxel_size, frame.voxel_size, 1e-15);
    EXPECT_EQ(voxel_set(back), slow_decode(vola_test::read_bytes(path), largest + 1));
  }
}

TEST(Binvox, EmptyTreesAndToolkitFramesRoundTrip) {
  const auto empty = vola::io::parse_binvox(vola::io::serialize_binvox(vola::Tree()), "empty");
  EXPECT_TRUE(empty.voxels.empty());
  EXPECT_EQ(empty.dims, (std::array<std::uint32_t, 3>{1, 1, 1}));
  vola::PointCloud cloud;
  cloud.xyz = {0, 0, 0, 10, 5, 2.5, 3, 3, 3};
  const vola::Tree toolkit = vola::build(cloud, {.depth = 2});
  const auto back = vola::io::parse_binvox(vola::io::serialize_binvox(toolkit), "toolkit");
  EXPECT_EQ(voxel_set(back), vola_test::voxel_set(toolkit));
  EXPECT_EQ(back.origin, toolkit.frame().origin);
  EXPECT_NEAR(back.voxel_size, toolkit.frame().voxel_size, 1e-15);
}

TEST(Binvox, TooLargeAGridIsRefusedBeforeWriting) {
  const std::vector<vola::Voxel> far = {{0, 0, 0}, {vola::io::kMaxBinvoxSide, 0, 0}};
  EXPECT_THROW(vola::io::serialize_binvox(vola::build_from_voxels(far, 7)), vola::InvalidArgument);
}

Bytes binvox_text(const std::string& header, const Bytes& runs) {
  Bytes b(header.begin(), header.end());
  b.insert(b.end(), runs.begin(), runs.end());
  return b;
}

TEST(Binvox, HeaderVariantsAndNonCubicGrids) {
  // dim A B C: x < A, z < B, y < C; index = x*B*C + z*C + y. Cells 0..23 of a 2x3x4
  // grid, only index 1*12 + 2*4 + 3 = 23 occupied -> x 1, z 2, y 3.
  const auto grid = vola::io::parse_binvox(
      binvox_text("#binvox 1\r\n# comment\r\n\r\nscale 8  # world size of the longest side\r\n\tdim 2 3 4\t\r\n"
                  "translate 1 -2 +3\r\ndata\r\n",
                  {0, 23, 1, 1}),
      "variant");
  ASSERT_EQ(grid.voxels.size(), 1u);
  EXPECT_EQ(grid.voxels[0], (vola::Voxel{1, 3, 2}));
  EXPECT_EQ(grid.dims, (std::array<std::uint32_t, 3>{2, 4, 3}));
  EXPECT_EQ(grid.origin, (vola::Point{1, -2, 3}));
  EXPECT_EQ(grid.voxel_size, 2.0);
}

TEST(Binvox, EveryTruncationIsAFormatError) {
  std::mt19937_64 rng(3);
  const Bytes full = vola::io::serialize_binvox(random_tree(rng, 2, 16, 300));
  for (std::size_t n = 0; n < full.size(); ++n) {
    const Bytes cut(full.begin(), full.begin() + static_cast<std::ptrdiff_t>(n));
    const auto error = vola_test::format_error_of([&] { vola::io::parse_binvox(cut, "cut.binvox"); });
    ASSERT_TRUE(error) << "cut at " << n;
    EXPECT_EQ(error->file(), "cut.binvox");
  }
}

TEST(Binvox, CorruptedInputIsAFormatErrorNamingTheProblem) {
  const std::string head = "#binvox 1\ndim 2 2 2\ntranslate 0 0 0\nscale 1\ndata\n";
  struct Case {
    Bytes bytes;
    std::string cause;
  } cases[] = {
      {binvox_text("P6\n", {}), "not a binvox file"},
      {binvox_text("#binvox 1\ndim 2 2 2\n", {}), "without a 'data' line"},
      {binvox_text("#binvox 1\ndim 2 2\ndata\n", {1, 4}), "expected 'dim A B C'"},
      {binvox_text("#binvox 1\ndim 2 0 2\ndata\n", {}), "not an integer 1.."},
      {binvox_text("#binvox 1\ndim 2 2 99999999999\ndata\n", {}), "not an integer 1.."},
      {binvox_text("#binvox 1\ndim 4000000000 4000000000 4000000000\ndata\n", {}), "more cells than 64 bits"},
      {binvox_text("#binvox 1\nscale -1\ndim 2 2 2\ndata\n", {1, 8}), "positive"},
      {binvox_text("#binvox 1\ntranslate 0 nan 0\ndim 2 2 2\ndata\n", {1, 8}), "finite"},
      // A denormal scale over 1000 cells: a voxel size of 0, which the .vol reader refuses.
      {binvox_text("#binvox 1\ndim 1000 1 1\nscale 4.9e-324\ndata\n", {1, 255, 1, 255, 1, 255, 1, 235}),
       "makes a voxel size of 0"},
      {binvox_text("#binvox 1\ncolour red\ndata\n", {}), "unknown header keyword"},
      {binvox_text("#binvox 1\ndata\n", {1, 8}), "no 'dim' line"},
      {binvox_text(head, {1, 4, 2, 4}), "run value 2"},
      {binvox_text(head, {1, 4, 0, 5}), "passes the grid"},
      {binvox_text(head, {1, 4, 0, 3}), "truncated"},
  };
  for (const auto& c : cases) {
    const auto error = vola_test::format_error_of([&] { vola::io::parse_binvox(c.bytes, "bad.binvox"); });
    ASSERT_TRUE(error) << std::string(c.bytes.begin(), c.bytes.end());
    EXPECT_NE(error->cause().find(c.cause), std::string::npos) << error->what() << "\nexpected: " << c.cause;
    EXPECT_TRUE(error->offset().has_value());
  }
  // Runs past the last cell are left alone (nothing follows in a binvox file).
  EXPECT_EQ(vola::io::parse_binvox(binvox_text(head, {1, 8, 0, 0, 7}), "tail").voxels.size(), 8u);
}

}  // namespace

namespace {

// 255 M cells in a 2 MB file, every run (1, 255): the reader expanded them into 3 GB of
// 12-byte voxels. Refused from the run count, under a 2 GiB address-space cap.
TEST(Binvox, RunsThatSetMoreVoxelsThanTheFileJustifiesAreRefused) {
  const std::size_t pairs = 1'000'000;
  Bytes bytes = binvox_text("#binvox 1\ndim 255 1000 1000\ndata\n", {});
  const std::size_t data_at = bytes.size();
  for (std::size_t i = 0; i < pairs; ++i) bytes.insert(bytes.end(), {1, 255});
  const std::string outcome = vola_test::run_with_memory_cap([&] {
    vola::io::parse_binvox(bytes, "solid.binvox");
    return std::string("read");
  });
  EXPECT_EQ(outcome.rfind("FormatError: solid.binvox: byte " + std::to_string(data_at) + ": the runs set 255000000 voxels", 0),
            0u)
      << outcome;
  // A fully solid 256^3 grid (65 793 run pairs) stays within the allowance.
  Bytes solid = binvox_text("#binvox 1\ndim 256 256 256\ndata\n", {});
  for (std::uint64_t left = 256u * 256u * 256u; left > 0; left -= std::min<std::uint64_t>(left, 255))
    solid.insert(solid.end(), {1, static_cast<std::uint8_t>(std::min<std::uint64_t>(left, 255))});
  EXPECT_EQ(vola::io::parse_binvox(solid, "cube.binvox").voxels.size(), 256u * 256u * 256u);
}

}  // namespace
