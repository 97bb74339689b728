// NPY dense grid export: points -> vol -> NPY -> the project's NPY reader -> vol keeps
// the voxel set; the array is uint8 (S, S, S) indexed [x, y, z]; level-of-detail
// export and the size limit.
#include <gtest/gtest.h>

#include "export_test_support.hpp"
#include "vola/io/export.hpp"
#include "vola/io/input.hpp"
#include "vola/io/npy.hpp"

namespace {

using namespace vola_export_test;
using vola_test::TempDir;
using vola_test::Xyz;
using vola_test::XyzSet;

// The occupied cells of a 3-D array, read element by element (the slow way).
XyzSet slow_cells_of(const vola::io::NpyArray& array) {
  XyzSet cells;
  const auto& s = array.shape;
  for (std::uint64_t x = 0; x < s[0]; ++x)
    for (std::uint64_t y = 0; y < s[1]; ++y)
      for (std::uint64_t z = 0; z < s[2]; ++z) {
        const double v = array.value((x * s[1] + y) * s[2] + z);
        EXPECT_TRUE(v == 0 || v == 1);
        if (v != 0)
          cells.insert({static_cast<std::uint32_t>(x), static_cast<std::uint32_t>(y), static_cast<std::uint32_t>(z)});
      }
  return cells;
}

class NpyRoundTrip : public ::testing::TestWithParam<int> {};

TEST_P(NpyRoundTrip, KeepsVoxels) {
  const int depth = GetParam();
  for (std::uint64_t seed = 0; seed < (depth <= 3 ? 6u : 2u); ++seed) {
    const Sample s = random_sample(4000 * depth + seed, depth, false);
    SCOPED_TRACE(s.describe);
    TempDir dir;
    const auto file = dir / "grid.npy";
    vola::io::write_npy_grid(s.tree, file.string());

    const vola::io::NpyArray array = vola::io::read_npy(file.string());
    const std::uint64_t side = s.tree.side();
    EXPECT_EQ(array.shape, (std::vector<std::uint64_t>{side, side, side}));
    EXPECT_EQ(array.kind, 'u');
    EXPECT_EQ(array.item_size, 1);
    EXPECT_FALSE(array.fortran_order);
    if (depth <= 3) {
      EXPECT_EQ(slow_cells_of(array), s.voxels);
    }

    // Through the input dispatch, as `vola convert grid.npy` reads it: one cell, one voxel.
    const vola::io::Input in = vola::io::read_input(file.string(), "auto", {});
    ASSERT_TRUE(in.grid.has_value()) << "the NPY reader did not read the array as a grid";
    EXPECT_EQ(in.grid->dims, (std::array<std::uint32_t, 3>{static_cast<std::uint32_t>(side),
                                                             static_cast<std::uint32_t>(side),
                                                             static_cast<std::uint32_t>(side)}));
    EXPECT_EQ(vola_test::voxel_set(vola::build_from_voxels(in.grid->voxels, depth)), s.voxels);
  }
}

INSTANTIATE_TEST_SUITE_P(Depths, NpyRoundTrip, ::testing::Range(1, 5));

TEST(NpyExport, HeaderIsVersionOneAlignedToSixtyFour) {
  TempDir dir;
  const auto file = dir / "g.npy";
  vola::io::write_npy_grid(random_sample(3, 2, false).tree, file.string());
  const auto bytes = vola_test::read_bytes(file);
  ASSERT_GE(bytes.size(), 10u);
  EXPECT_EQ(std::string(bytes.begin(), bytes.begin() + 6), "\x93NUMPY");
  EXPECT_EQ(bytes[6], 1);
  EXPECT_EQ(bytes[7], 0);
  const std::size_t data = 10 + vola_test::get_le<std::uint16_t>(bytes, 8);
  EXPECT_EQ(data % 64, 0u);
  EXPECT_EQ(bytes[data - 1], '\n');
  EXPECT_EQ(bytes.size(), data + 16 * 16 * 16);
  const std::string dict(bytes.begin() + 10, bytes.begin() + static_cast<std::ptrdiff_t>(data));
  EXPECT_NE(dict.find("'shape': (16, 16, 16)"), std::string::npos) << dict;
}

TEST(NpyExport, LevelOfDetailIsTheCoarseGrid) {
  const Sample s = random_sample(9, 6, false);
  for (int depth = 1; depth <= 3; ++depth) {
    TempDir dir;
    const auto file = dir / "lod.npy";
    vola::io::write_npy_grid(s.tree.level_of_detail(depth), file.string());
    EXPECT_EQ(slow_cells_of(vola::io::read_npy(file.string())), vola_test::slow_cells(s.voxels, depth - 1, 6));
  }
}

TEST(NpyExport, RefusesGridsBeyondTheLimit) {
  const vola::Tree deep = vola::build_from_voxels(std::vector<vola::Voxel>{{1, 2, 3}}, vola::io::kMaxNpyDepth + 1);
  TempDir dir;
  const auto file = dir / "big.npy";
  try {
    vola::io::write_npy_grid(deep, file.string());
    FAIL() << "a 4096^3 grid was not refused";
  } catch (const vola::OptionError& e) {
    // The option to give, as each front end spells it (--depth, depth=).
    EXPECT_EQ(e.option(), "depth") << e.what();
    EXPECT_NE(e.cause().find("coarser"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(vola_test::fs::exists(file));
}

}  // namespace
