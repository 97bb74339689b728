// GeoTIFF rasters' cells (vola::io::make_raster) against a slow model computed from the
// voxel set and the grid: every product, cells of the voxel size, of 2.5 and of 7/6 voxels,
// north-up rows, the crop and the geotransform; the refusals. The file itself (GDAL,
// CRS, COG layout) is read back in tests/io/cli_raster.sh.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <map>
#include <utility>
#include <vector>

#include "export_test_support.hpp"
#include "vola/error.hpp"
#include "vola/io/export.hpp"

namespace {

using namespace vola_export_test;
using vola::io::RasterProduct;
using vola_test::Xyz;

struct Expected {
  std::uint64_t width = 0, height = 0;
  std::array<double, 6> geotransform{};
  std::vector<double> values;  // NaN: no value
};

// The model: cells of num / den voxels; voxel column i, centred (2i + 1) / 2 voxels from the
// origin, is in cell floor((2i + 1) den / (2 num)), in integers (a centre on a border in
// the cell above it); rows from the north.
Expected slow_raster(const Sample& s, RasterProduct product, std::int64_t num, std::int64_t den) {
  const double voxel = s.grid.voxel_size, cell = voxel * static_cast<double>(num) / static_cast<double>(den);
  auto cell_of = [&](std::uint32_t i) -> std::int64_t { return (2 * std::int64_t{i} + 1) * den / (2 * num); };
  std::map<std::pair<std::int64_t, std::int64_t>, std::vector<Xyz>> cells;
  for (const Xyz& v : s.voxels) cells[{cell_of(v[0]), cell_of(v[1])}].push_back(v);
  std::int64_t u0 = std::numeric_limits<std::int64_t>::max(), v0 = u0, u1 = -1, v1 = -1;
  for (const auto& [uv, voxels] : cells) {
    u0 = std::min(u0, uv.first), u1 = std::max(u1, uv.first);
    v0 = std::min(v0, uv.second), v1 = std::max(v1, uv.second);
  }
  Expected e;
  e.width = static_cast<std::uint64_t>(u1 - u0 + 1);
  e.height = static_cast<std::uint64_t>(v1 - v0 + 1);
  const auto& o = s.grid.origin;
  e.geotransform = {o[0] + static_cast<double>(u0) * cell, cell, 0.0, o[1] + static_cast<double>(v1 + 1) * cell, 0.0,
                    -cell};
  e.values.assign(e.width * e.height, std::nan(""));
  for (const auto& [uv, voxels] : cells) {
    double value = 0.0;
    for (const Xyz& v : voxels) {
      const double bottom = o[2] + v[2] * voxel, top = o[2] + (v[2] + 1.0) * voxel;
      switch (product) {
        case RasterProduct::dsm: value = &v == &voxels.front() ? top : std::max(value, top); break;
        case RasterProduct::dtm: value = &v == &voxels.front() ? bottom : std::min(value, bottom); break;
        default: value += 1.0;
      }
    }
    if (product == RasterProduct::density) value /= cell * cell;
    e.values[static_cast<std::uint64_t>(v1 - uv.second) * e.width + static_cast<std::uint64_t>(uv.first - u0)] = value;
  }
  return e;
}

class RasterCells : public ::testing::TestWithParam<int> {};

TEST_P(RasterCells, MatchTheVoxelColumns) {
  const int depth = GetParam();
  for (std::uint64_t seed = 0; seed < 4; ++seed) {
    const Sample s = random_sample(7100 * depth + seed, depth, false);
    SCOPED_TRACE(s.describe);
    // 7/6: a border's quotient rounds either way in doubles (columns went to either side).
    for (const auto& [num, den] : {std::pair<std::int64_t, std::int64_t>{1, 1}, {5, 2}, {7, 6}}) {
      const double ratio = static_cast<double>(num) / static_cast<double>(den);
      for (const RasterProduct product :
           {RasterProduct::dsm, RasterProduct::dtm, RasterProduct::density, RasterProduct::count}) {
        SCOPED_TRACE(std::string(vola::io::raster_product_name(product)) + ", cells of " + std::to_string(ratio) +
                     " voxels");
        vola::io::RasterOptions options;
        options.product = product;
        options.resolution = ratio == 1.0 ? 0.0 : ratio * s.grid.voxel_size;
        const vola::io::Raster r = vola::io::make_raster(s.tree, options);
        const Expected e = slow_raster(s, product, num, den);
        ASSERT_EQ(r.width, e.width);
        ASSERT_EQ(r.height, e.height);
        for (int i = 0; i < 6; ++i) EXPECT_DOUBLE_EQ(r.geotransform[i], e.geotransform[i]) << "geotransform " << i;
        ASSERT_EQ(r.values.size(), e.values.size());
        std::uint64_t with_value = 0;
        for (std::size_t i = 0; i < e.values.size(); ++i) {
          if (std::isnan(e.values[i])) {
            EXPECT_EQ(r.values[i], vola::io::kRasterNodata) << "cell " << i;
          } else {
            ++with_value;
            EXPECT_FLOAT_EQ(r.values[i], static_cast<float>(e.values[i])) << "cell " << i;
          }
        }
        EXPECT_EQ(r.cells_with_data, with_value);
        // Cropped: the first and last rows and columns each hold a value.
        auto any = [&](std::uint64_t c0, std::uint64_t r0, std::uint64_t dc, std::uint64_t dr, std::uint64_t n) {
          for (std::uint64_t k = 0; k < n; ++k)
            if (r.values[(r0 + k * dr) * r.width + c0 + k * dc] != vola::io::kRasterNodata) return true;
          return false;
        };
        EXPECT_TRUE(any(0, 0, 1, 0, r.width) && any(0, r.height - 1, 1, 0, r.width) && any(0, 0, 0, 1, r.height) &&
                    any(r.width - 1, 0, 0, 1, r.height));
      }
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Depths, RasterCells, ::testing::Values(1, 2, 3, 4, 5));

// With attributes: intensity is the mean over the cell's columns of each column's top
// voxel; dtm keeps to classification 2 when any voxel has it.
TEST(RasterAttributes, IntensityOfTopVoxelsAndGroundOnlyDtm) {
  int with_ground = 0;
  for (std::uint64_t seed = 0; seed < 6; ++seed) {
    const Sample s = random_sample(7300 + seed, 3, true);
    SCOPED_TRACE(s.describe);
    const auto* intensity = s.tree.attributes().find("intensity");
    const auto* classes = s.tree.attributes().find("classification");
    ASSERT_TRUE(intensity && classes);
    std::map<std::pair<std::uint32_t, std::uint32_t>, Xyz> tops;  // per column, its highest voxel
    bool any_ground = false;
    for (const Xyz& v : s.voxels) {
      auto [it, added] = tops.try_emplace({v[0], v[1]}, v);
      if (!added && it->second[2] < v[2]) it->second = v;
      any_ground |= classes->get(*s.tree.rank(vola_test::to_voxel(v))) == 2.0;
    }
    vola::io::RasterOptions options;
    options.product = RasterProduct::intensity;
    const vola::io::Raster r = vola::io::make_raster(s.tree, options);
    const Expected shape = slow_raster(s, RasterProduct::count, 1, 1);
    ASSERT_EQ(r.width, shape.width);
    // The voxel column of the first cell, and the row past the northernmost.
    const double voxel = s.grid.voxel_size;
    const auto x0 = static_cast<std::uint32_t>(std::lround((shape.geotransform[0] - s.grid.origin[0]) / voxel));
    const auto y1 = static_cast<std::uint32_t>(std::lround((shape.geotransform[3] - s.grid.origin[1]) / voxel));
    for (const auto& [column, top] : tops) {
      const double want = intensity->get(*s.tree.rank(vola_test::to_voxel(top)));
      EXPECT_FLOAT_EQ(r.values[(y1 - 1 - column.second) * r.width + (column.first - x0)], static_cast<float>(want));
    }

    options.product = RasterProduct::dtm;
    const vola::io::Raster dtm = vola::io::make_raster(s.tree, options);
    std::map<std::pair<std::uint32_t, std::uint32_t>, double> lowest;
    for (const Xyz& v : s.voxels) {
      if (any_ground && classes->get(*s.tree.rank(vola_test::to_voxel(v))) != 2.0) continue;
      const double bottom = s.grid.origin[2] + v[2] * voxel;
      auto [it, added] = lowest.try_emplace({v[0], v[1]}, bottom);
      if (!added) it->second = std::min(it->second, bottom);
    }
    with_ground += any_ground;
    EXPECT_EQ(dtm.cells_with_data, lowest.size());
    for (const auto& [column, bottom] : lowest)
      EXPECT_FLOAT_EQ(dtm.values[(y1 - 1 - column.second) * dtm.width + (column.first - x0)],
                      static_cast<float>(bottom));
  }
  EXPECT_GT(with_ground, 0) << "no sample had a ground voxel: the ground rule went untested";
}

TEST(RasterRefusals, SayWhy) {
  const Sample s = random_sample(7400, 3, false);
  vola::io::RasterOptions options;
  options.resolution = s.grid.voxel_size / 2;
  EXPECT_THROW(vola::io::make_raster(s.tree, options), vola::InvalidArgument);
  options.resolution = -1.0;
  EXPECT_THROW(vola::io::make_raster(s.tree, options), vola::InvalidArgument);
  options.resolution = 0.0;
  options.product = RasterProduct::intensity;  // no intensity column
  EXPECT_THROW(vola::io::make_raster(s.tree, options), vola::InvalidArgument);
  options.product = RasterProduct::count;
  EXPECT_THROW(vola::io::make_raster(vola::Tree{}, options), vola::InvalidArgument);
  EXPECT_EQ(vola::io::raster_product("dtm"), RasterProduct::dtm);
  EXPECT_FALSE(vola::io::raster_product("dem").has_value());
}

}  // namespace
