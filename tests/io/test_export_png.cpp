// PNG export: slices, height maps and occupancy maps decoded with libpng and compared
// pixel by pixel with a std::set of the voxels.
#include <gtest/gtest.h>
#include <png.h>

#include <csetjmp>
#include <cstdio>
#include <map>

#include "export_test_support.hpp"
#include "vola/io/export.hpp"

namespace {

using namespace vola_export_test;
using vola_test::TempDir;
using vola_test::Xyz;
using vola_test::XyzSet;

struct Image {
  std::uint32_t width = 0, height = 0;
  int bits = 0;
  int colour_type = -1;
  std::vector<std::uint16_t> pixels;  // row after row, top row first
  std::uint16_t at(std::uint64_t column, std::uint64_t row) const { return pixels[row * width + column]; }
};

// Reads the rows; false on a libpng error. Only `png`, `info` and `image` (through
// the pointer) are used after the jump, none of them changed after the setjmp.
bool read_rows(png_structp png, png_infop info, Image* image) {
  if (setjmp(png_jmpbuf(png))) return false;
  png_read_info(png, info);
  image->width = png_get_image_width(png, info);
  image->height = png_get_image_height(png, info);
  image->bits = png_get_bit_depth(png, info);
  image->colour_type = png_get_color_type(png, info);
  if (image->bits == 16) png_set_swap(png);
  png_read_update_info(png, info);
  std::vector<std::uint8_t> row(png_get_rowbytes(png, info));
  for (std::uint32_t r = 0; r < image->height; ++r) {
    png_read_row(png, row.data(), nullptr);
    for (std::uint32_t c = 0; c < image->width; ++c) {
      std::uint16_t v = row[c];
      if (image->bits == 16) std::memcpy(&v, &row[2 * c], 2);
      image->pixels.push_back(v);
    }
  }
  png_read_end(png, nullptr);
  return true;
}

Image decode(const vola_test::fs::path& file) {
  Image image;
  std::FILE* f = std::fopen(file.c_str(), "rb");
  if (!f) {
    ADD_FAILURE() << "cannot open " << file;
    return image;
  }
  png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  png_infop info = png_create_info_struct(png);
  png_init_io(png, f);
  const bool ok = read_rows(png, info, &image);
  png_destroy_read_struct(&png, &info, nullptr);
  std::fclose(f);
  EXPECT_TRUE(ok) << "libpng could not decode " << file;
  return image;
}

class PngSlices : public ::testing::TestWithParam<int> {};

TEST_P(PngSlices, OneImagePerZWithTheVoxelsWhite) {
  const int depth = GetParam();
  for (std::uint64_t seed = 0; seed < (depth <= 3 ? 4u : 1u); ++seed) {
    const Sample s = random_sample(5000 * depth + seed, depth, false);
    SCOPED_TRACE(s.describe);
    TempDir dir;
    const auto out = dir / "slices";
    const std::uint32_t side = s.tree.side();
    EXPECT_EQ(vola::io::write_png_slices(s.tree, out.string()), side);
    std::size_t files = 0;
    for (const auto& entry : vola_test::fs::directory_iterator(out)) {
      (void)entry;
      ++files;
    }
    EXPECT_EQ(files, side);
    for (std::uint32_t z = 0; z < side; ++z) {
      char name[32];
      std::snprintf(name, sizeof name, "depth%d-%03u.png", depth, z);
      const Image image = decode(out / name);
      ASSERT_EQ(image.width, side);
      ASSERT_EQ(image.height, side);
      ASSERT_EQ(image.bits, 8);
      ASSERT_EQ(image.colour_type, PNG_COLOR_TYPE_GRAY);
      for (std::uint32_t y = 0; y < side; ++y)
        for (std::uint32_t x = 0; x < side; ++x)
          ASSERT_EQ(image.at(x, side - 1 - y), s.voxels.count({x, y, z}) ? 255 : 0) << x << " " << y << " " << z;
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Depths, PngSlices, ::testing::Range(1, 5));

// Per (x, y), the highest occupied z, from the set.
std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint32_t> slow_tops(const XyzSet& voxels) {
  std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint32_t> tops;
  for (const auto& v : voxels) {
    auto [it, fresh] = tops.try_emplace({v[0], v[1]}, v[2]);
    if (!fresh) it->second = std::max(it->second, v[2]);
  }
  return tops;
}

class PngMaps : public ::testing::TestWithParam<int> {};

TEST_P(PngMaps, HeightAndOccupancyMatchTheColumns) {
  const int depth = GetParam();
  const Sample s = random_sample(6000 + depth, depth, false);
  SCOPED_TRACE(s.describe);
  const std::uint32_t side = s.tree.side();
  const auto tops = slow_tops(s.voxels);
  auto top_of = [&](std::uint32_t x, std::uint32_t y) -> std::optional<std::uint32_t> {
    const auto it = tops.find({x, y});
    if (it == tops.end()) return std::nullopt;
    return it->second;
  };
  TempDir dir;
  const auto map16 = dir / "h16.png", map8 = dir / "h8.png";
  vola::io::write_png_height_map(s.tree, map16.string(), 16);
  vola::io::write_png_height_map(s.tree, map8.string(), 8);
  const Image h16 = decode(map16), h8 = decode(map8);
  ASSERT_EQ(h16.bits, 16);
  ASSERT_EQ(h8.bits, 8);
  ASSERT_EQ(h16.width, side);
  ASSERT_EQ(h8.height, side);
  for (std::uint32_t y = 0; y < side; ++y)
    for (std::uint32_t x = 0; x < side; ++x) {
      const auto top = top_of(x, y);
      const std::uint32_t row = side - 1 - y;
      ASSERT_EQ(h16.at(x, row), top ? *top + 1 : 0);
      ASSERT_EQ(h8.at(x, row), top ? 1 + std::lround(*top * 254.0 / (side - 1)) : 0);
    }
  for (const std::uint32_t above : {0u, side / 2, side - 1, side}) {
    const auto file = dir / ("above" + std::to_string(above) + ".png");
    vola::io::write_png_occupancy_above(s.tree, file.string(), above);
    const Image occupancy = decode(file);
    ASSERT_EQ(occupancy.bits, 8);
    for (std::uint32_t y = 0; y < side; ++y)
      for (std::uint32_t x = 0; x < side; ++x) {
        const auto top = top_of(x, y);
        ASSERT_EQ(occupancy.at(x, side - 1 - y), top && *top >= above ? 0 : 255) << "above " << above;
      }
  }
}

INSTANTIATE_TEST_SUITE_P(Depths, PngMaps, ::testing::Range(1, 7));

TEST(PngExport, SliceFileNamesGrowWithTheSide) {
  // Depth 5 has 1024 slices: four digits, so that the names sort.
  const vola::Tree tree = vola::build_from_voxels(std::vector<vola::Voxel>{{1, 2, 1023}}, 5);
  TempDir dir;
  vola::io::write_png_slices(tree, (dir / "s").string());
  EXPECT_TRUE(vola_test::fs::exists(dir / "s" / "depth5-0000.png"));
  const Image last = decode(dir / "s" / "depth5-1023.png");
  EXPECT_EQ(last.at(1, 1023 - 2), 255);
}

TEST(PngExport, RefusesImagesBeyondTheLimits) {
  TempDir dir;
  const vola::Tree deep6 = vola::build_from_voxels(std::vector<vola::Voxel>{{1, 2, 3}}, 6);
  const vola::Tree deep8 = vola::build_from_voxels(std::vector<vola::Voxel>{{1, 2, 3}}, 8);
  EXPECT_THROW(vola::io::write_png_slices(deep6, (dir / "s").string()), vola::InvalidArgument);
  EXPECT_THROW(vola::io::write_png_height_map(deep8, (dir / "h.png").string()), vola::InvalidArgument);
  EXPECT_THROW(vola::io::write_png_occupancy_above(deep8, (dir / "o.png").string(), 0), vola::InvalidArgument);
  EXPECT_THROW(vola::io::write_png_height_map(deep6, (dir / "h.png").string(), 12), vola::InvalidArgument);
  EXPECT_FALSE(vola_test::fs::exists(dir / "h.png"));
}

TEST(PngExport, UnwritablePathIsAnIoError) {
  TempDir dir;
  const vola::Tree tree = vola::build_from_voxels(std::vector<vola::Voxel>{{1, 2, 3}}, 2);
  EXPECT_THROW(vola::io::write_png_height_map(tree, (dir / "no" / "h.png").string()), vola::IoError);
}

}  // namespace
