// NPY occupancy grids: 3-D arrays of every dtype and both memory orders against the
// slow NpyArray::value() reference; point arrays stay points; stacks of grids get an
// error that says what to do.
#include <gtest/gtest.h>

#include <random>

#include "io_test_data.hpp"
#include "vola/io/input.hpp"
#include "vola/io/npy.hpp"

namespace {

using namespace vola_io_test;
using vola_test::Xyz;
using vola_test::XyzSet;

// The occupied cells by the slow path: value() takes a C-order index whatever the
// file's order, and converts to double.
XyzSet slow_occupied(const vola::io::NpyArray& a) {
  XyzSet cells;
  for (std::uint32_t x = 0; x < a.shape[0]; ++x)
    for (std::uint32_t y = 0; y < a.shape[1]; ++y)
      for (std::uint32_t z = 0; z < a.shape[2]; ++z)
        if (a.value((x * a.shape[1] + y) * a.shape[2] + z) != 0.0) cells.insert({x, y, z});
  return cells;
}

// Random values of `dtype`, about a third of them zero; floats also get -0.0 (empty)
// and NaN (occupied, as numpy.count_nonzero says).
Bytes random_values(const std::string& dtype, std::size_t count, std::mt19937_64& rng) {
  const bool big = dtype[0] == '>';
  const char kind = dtype[1];
  const int size = dtype[2] - '0';
  Bytes out;
  for (std::size_t i = 0; i < count; ++i) {
    const int pick = static_cast<int>(rng() % 6);
    const bool zero = pick < 2;
    if (kind == 'f') {
      double v = zero ? (pick == 0 ? 0.0 : -0.0) : pick == 2 ? std::numeric_limits<double>::quiet_NaN()
                                                               : static_cast<double>(rng() % 1000) - 500.5;
      if (size == 4) put<float>(out, static_cast<float>(v), big);
      else put<double>(out, v, big);
    } else if (kind == 'b') {
      out.push_back(zero ? 0 : 1);
    } else {
      // A non-zero value whose low byte may be zero: every byte counts.
      const std::uint64_t v = zero ? 0 : (pick == 2 ? std::uint64_t{1} << (8 * (size - 1)) : rng());
      std::uint8_t raw[8];
      std::memcpy(raw, &v, 8);
      if (v && std::all_of(raw, raw + size, [](std::uint8_t b) { return b == 0; })) raw[0] = 1;
      for (int b = 0; b < size; ++b) out.push_back(raw[big ? size - 1 - b : b]);
    }
  }
  return out;
}

TEST(NpyGrid, EveryDtypeAndOrderMatchesTheSlowReference) {
  std::mt19937_64 rng(7);
  for (const std::string dtype : {"|b1", "|u1", "|i1", "<i2", ">u2", "<i4", ">i8", "<u8", "<f4", ">f4", "<f8", ">f8"})
    for (const bool fortran : {false, true}) {
      SCOPED_TRACE(dtype + (fortran ? " Fortran order" : " C order"));
      const std::vector<std::uint64_t> shape = {3, 5, 4};
      const Bytes bytes = npy_bytes(dtype, shape, fortran, random_values(dtype, 60, rng));
      const vola::io::NpyArray array = vola::io::parse_npy(bytes, "grid.npy");
      const vola::io::Input in = vola::io::npy_input(array, "grid.npy", {});
      ASSERT_TRUE(in.grid.has_value());
      EXPECT_EQ(in.grid->dims, (std::array<std::uint32_t, 3>{3, 5, 4}));
      EXPECT_EQ(in.grid->origin, (vola::Point{0, 0, 0}));
      EXPECT_EQ(in.grid->voxel_size, 1.0);
      XyzSet fast;
      for (const auto& v : in.grid->voxels) fast.insert(vola_test::to_xyz(v));
      EXPECT_EQ(fast.size(), in.grid->voxels.size());  // no cell twice
      EXPECT_EQ(fast, slow_occupied(array));
      EXPECT_FALSE(fast.empty());
    }
}

TEST(NpyGrid, AxisOrderIsFirstIndexX) {
  // One occupied cell at [1][2][3] of a (2, 3, 4) C-order uint8 array.
  Bytes data(24, 0);
  data[(1 * 3 + 2) * 4 + 3] = 1;
  const auto in = vola::io::npy_input(vola::io::parse_npy(npy_bytes("|u1", {2, 3, 4}, false, data), "one.npy"),
                                      "one.npy", {});
  ASSERT_EQ(in.grid->voxels.size(), 1u);
  EXPECT_EQ(in.grid->voxels[0], (vola::Voxel{1, 2, 3}));
  // The same cell in a Fortran-order file: storage index 1 + 2*2 + 3*2*3.
  Bytes fortran(24, 0);
  fortran[1 + 2 * 2 + 3 * 2 * 3] = 1;
  const auto f = vola::io::npy_input(vola::io::parse_npy(npy_bytes("|u1", {2, 3, 4}, true, fortran), "f.npy"), "f.npy", {});
  ASSERT_EQ(f.grid->voxels.size(), 1u);
  EXPECT_EQ(f.grid->voxels[0], (vola::Voxel{1, 2, 3}));
}

TEST(NpyGrid, PointArraysStayPointsAndStacksAreRefused) {
  Bytes points;
  for (double v : {1.0, 2.0, 3.0, 4.0, 5.0, 6.0}) put<double>(points, v);
  const auto p = vola::io::npy_input(vola::io::parse_npy(npy_bytes("<f8", {2, 3}, false, points), "p.npy"), "p.npy", {});
  EXPECT_FALSE(p.grid.has_value());
  EXPECT_EQ(p.cloud.xyz, (std::vector<double>{1, 2, 3, 4, 5, 6}));

  const auto stack = vola::io::parse_npy(npy_bytes("|u1", {2, 2, 2, 2}, false, Bytes(16, 1)), "stack.npy");
  const auto error = vola_test::format_error_of([&] { vola::io::npy_input(stack, "stack.npy", {}); });
  ASSERT_TRUE(error);
  EXPECT_NE(error->cause().find("pick one"), std::string::npos) << error->what();
  const auto flat = vola::io::parse_npy(npy_bytes("|u1", {4}, false, Bytes(4, 1)), "flat.npy");
  EXPECT_TRUE(vola_test::format_error_of([&] { vola::io::npy_input(flat, "flat.npy", {}); }));
}

TEST(NpyGrid, PointsSavedAsRowsOfXYZAreRefusedNotReadAsThreePoints) {
  // numpy.save(f, points.T): 3 rows of 12 columns read as rows would be 3 points.
  Bytes rows;
  for (int v = 0; v < 36; ++v) put<double>(rows, v);
  const auto transposed = vola::io::parse_npy(npy_bytes("<f8", {3, 12}, false, rows), "t.npy");
  const auto error = vola_test::format_error_of([&] { vola::io::npy_input(transposed, "t.npy", {}); });
  ASSERT_TRUE(error);
  EXPECT_NE(error->cause().find("(3, 12) reads as 3 points of 12 columns"), std::string::npos) << error->what();
  EXPECT_NE(error->cause().find("points.T"), std::string::npos) << error->what();
  // Three points of x, y, z and an 8-column payload are three points; twelve are twelve.
  const auto payload =
      vola::io::parse_npy(npy_bytes("<f8", {3, 11}, false, Bytes(rows.begin(), rows.begin() + 264)), "p.npy");
  EXPECT_EQ(vola::io::npy_input(payload, "p.npy", {}).cloud.size(), 3u);
  const auto twelve = vola::io::parse_npy(npy_bytes("<f8", {12, 3}, false, rows), "r.npy");
  EXPECT_EQ(vola::io::npy_input(twelve, "r.npy", {}).cloud.size(), 12u);
}

TEST(NpyGrid, ACompressedArrayGivesNoMoreThanItsCompressedBytesJustify) {
  // numpy.savez_compressed of a 600^3 grid of ones is 210 KB: 216 M voxels of 12 bytes.
  // A compressed member is held to 2^25 + 8 values per compressed byte, as binvox's runs.
  auto small = vola::io::parse_npy(npy_bytes("|u1", {4, 4, 4}, false, Bytes(64, 1)), "g.npz:a.npy");
  small.compressed_bytes = 1;
  EXPECT_EQ(vola::io::npy_grid(small, "g.npz:a.npy").voxels.size(), 64u);  // within the allowance
  const std::uint64_t limit = vola::io::kNpyValuesAllowance + vola::io::kNpyValuesPerStoredByte;
  auto big = vola::io::parse_npy(npy_bytes("|u1", {limit + 1, 1, 1}, false, Bytes(limit + 1, 1)), "big.npz:a.npy");
  big.compressed_bytes = 1;
  const auto error = vola_test::format_error_of([&] { vola::io::npy_grid(big, "big.npz:a.npy"); });
  ASSERT_TRUE(error);
  EXPECT_NE(error->cause().find(std::to_string(limit + 1) + " occupied cells from 1 compressed bytes"),
            std::string::npos)
      << error->what();
  big.compressed_bytes = 0;  // the same array stored uncompressed: its bytes are its cells
  EXPECT_EQ(vola::io::npy_grid(big, "big.npy").voxels.size(), limit + 1);
}

TEST(NpyGrid, ReadInputDispatchesOnTheShape) {
  vola_test::TempDir dir;
  Bytes cells(8, 0);
  cells[7] = 1;
  vola_test::write_bytes(dir / "cube.npy", npy_bytes("|b1", {2, 2, 2}, false, cells));
  const auto in = vola::io::read_input((dir / "cube.npy").string(), "auto", {});
  EXPECT_EQ(in.format, "npy");
  ASSERT_TRUE(in.grid);
  ASSERT_EQ(in.grid->voxels.size(), 1u);
  EXPECT_EQ(in.grid->voxels[0], (vola::Voxel{1, 1, 1}));
  // A truncated grid is the npy parser's FormatError.
  Bytes cut = npy_bytes("<f4", {4, 4, 4}, false, Bytes(100, 0));
  EXPECT_TRUE(vola_test::format_error_of([&] { vola::io::parse_npy(cut, "cut.npy"); }));
}

}  // namespace
