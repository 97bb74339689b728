// Dilate, erode, fill, crop and downsample against brute-force twins on std::set models.
#include <gtest/gtest.h>

#include <map>

#include "analysis_models.hpp"
#include "vola/analysis/crop.hpp"
#include "vola/analysis/downsample.hpp"
#include "vola/analysis/fill.hpp"
#include "vola/analysis/morphology.hpp"

namespace vola_analysis_test {
namespace {

using vola::analysis::Element;

TEST(Morphology, DilateAndErodeMatchTheModel) {
  for (const Grid& g : random_grids(3)) {
    const vola::Tree t = tree_of(g.voxels, g.depth);
    for (Element e : {Element::sphere, Element::cube})
      for (int r : {0, 1, 2, 3, 5}) {
        if (r >= static_cast<int>(vola::side_of(g.depth))) continue;
        if (g.depth >= 3 && r == 5 && g.voxels.size() > 20000) continue;  // the model is slow there
        SCOPED_TRACE(g.name + (e == Element::cube ? " cube r" : " sphere r") + std::to_string(r));
        EXPECT_EQ(vola_test::voxel_set(vola::analysis::dilate(t, r, e)), model_dilate(g.voxels, g.depth, r, e));
        EXPECT_EQ(vola_test::voxel_set(vola::analysis::erode(t, r, e)), model_erode(g.voxels, g.depth, r, e));
      }
  }
}

TEST(Morphology, ErodeOfDilatedBallKeepsItsCore) {
  XyzSet ball;
  for (std::uint32_t z = 0; z < 64; ++z)
    for (std::uint32_t y = 0; y < 64; ++y)
      for (std::uint32_t x = 0; x < 64; ++x) {
        const int dx = int(x) - 30, dy = int(y) - 31, dz = int(z) - 29;
        if (dx * dx + dy * dy + dz * dz <= 100) ball.insert({x, y, z});
      }
  const vola::Tree t = tree_of(ball, 3);
  const vola::Tree grown = vola::analysis::dilate(t, 4, Element::sphere);
  EXPECT_EQ(vola_test::voxel_set(grown), model_dilate(ball, 3, 4, Element::sphere));
  EXPECT_EQ(vola_test::voxel_set(vola::analysis::erode(grown, 4, Element::sphere)),
            model_erode(model_dilate(ball, 3, 4, Element::sphere), 3, 4, Element::sphere));
}

TEST(Morphology, KeepsFrameAndGeoref) {
  vola::Tree t = tree_of({{1, 2, 3}}, 2);
  t.set_frame({vola::Quantization::grid, {100, 200, 5}, 0.5});
  t.georef().epsg = 32610;
  for (const vola::Tree& r : {vola::analysis::dilate(t, 1, Element::cube), vola::analysis::erode(t, 1, Element::cube),
                              vola::analysis::fill_cavities(t), vola::analysis::crop(t, {0, 0, 0}, {3, 3, 3})}) {
    ASSERT_TRUE(r.stored_frame());
    EXPECT_EQ(*r.stored_frame(), *t.stored_frame());
    EXPECT_EQ(r.georef().epsg, 32610u);
  }
}

TEST(Morphology, RadiusOutsideTheGridIsRefused) {
  const vola::Tree t = tree_of({{1, 2, 3}}, 1);
  EXPECT_THROW(vola::analysis::dilate(t, 4, Element::cube), vola::InvalidArgument);
  EXPECT_THROW(vola::analysis::erode(t, -1, Element::sphere), vola::InvalidArgument);
}

TEST(Fill, MatchesTheModelOnRandomGridsAndShells) {
  for (const Grid& g : random_grids(4)) {
    if (g.depth > 4) continue;  // the dense model's box would be the whole grid
    SCOPED_TRACE(g.name);
    vola::analysis::FillReport report;
    const vola::Tree filled = vola::analysis::fill_cavities(tree_of(g.voxels, g.depth), &report);
    const XyzSet model = model_fill(g.voxels);
    EXPECT_EQ(vola_test::voxel_set(filled), model);
    EXPECT_EQ(report.filled, model.size() - g.voxels.size());
  }
  // A hollow box with a hollow box inside it: both cavities fill, 8x8x8 - 0 holes.
  XyzSet shell;
  for (std::uint32_t z = 2; z < 10; ++z)
    for (std::uint32_t y = 2; y < 10; ++y)
      for (std::uint32_t x = 2; x < 10; ++x)
        if (x == 2 || x == 9 || y == 2 || y == 9 || z == 2 || z == 9 || ((x == 4 || x == 7 || y == 4 || y == 7 || z == 4 || z == 7) &&
                                                                          x >= 4 && x <= 7 && y >= 4 && y <= 7 && z >= 4 && z <= 7))
          shell.insert({x, y, z});
  const vola::Tree filled = vola::analysis::fill_cavities(tree_of(shell, 2));
  EXPECT_EQ(filled.voxel_count(), 512u);
  // A hole in one wall lets the outside in: only the inner box's cavity fills.
  shell.erase({2, 5, 5});
  EXPECT_EQ(vola::analysis::fill_cavities(tree_of(shell, 2)).voxel_count(), shell.size() + 8u);
  // Two opposite corners of a depth-8 grid: a box of 2^48 cells is refused.
  EXPECT_THROW(vola::analysis::fill_cavities(tree_of({{0, 0, 0}, {65535, 65535, 65535}}, 8)), vola::InvalidArgument);
}

TEST(Crop, MatchesTheModel) {
  std::mt19937_64 rng(5);
  for (const Grid& g : random_grids(5)) {
    const std::uint32_t s = vola::side_of(g.depth);
    std::uniform_int_distribution<std::uint32_t> any(0, s - 1);
    for (int i = 0; i < 4; ++i) {
      vola::Voxel a{any(rng), any(rng), any(rng)}, b{any(rng), any(rng), any(rng)};
      const vola::Voxel lo{std::min(a.x, b.x), std::min(a.y, b.y), std::min(a.z, b.z)};
      const vola::Voxel hi{std::max(a.x, b.x), std::max(a.y, b.y), std::max(a.z, b.z)};
      XyzSet model;
      for (const Xyz& v : g.voxels)
        if (v[0] >= lo.x && v[0] <= hi.x && v[1] >= lo.y && v[1] <= hi.y && v[2] >= lo.z && v[2] <= hi.z) model.insert(v);
      EXPECT_EQ(vola_test::voxel_set(vola::analysis::crop(tree_of(g.voxels, g.depth), lo, hi)), model) << g.name;
    }
  }
}

TEST(Downsample, MatchesTheModelAndLevelOfDetail) {
  for (const Grid& g : random_grids(6)) {
    const vola::Tree t = tree_of(g.voxels, g.depth);
    for (int depth = 1; depth <= g.depth; ++depth)
      for (std::uint64_t min_voxels : {1u, 2u, 5u}) {
        std::map<Xyz, std::uint64_t> counts;
        const int shift = 2 * (g.depth - depth);
        for (const Xyz& v : g.voxels) ++counts[{v[0] >> shift, v[1] >> shift, v[2] >> shift}];
        XyzSet model;
        for (const auto& [cell, n] : counts)
          if (n >= min_voxels) model.insert(cell);
        const vola::Tree d = vola::analysis::downsample(t, depth, min_voxels);
        EXPECT_EQ(d.depth(), depth);
        EXPECT_EQ(vola_test::voxel_set(d), model) << g.name << " to depth " << depth;
        if (min_voxels == 1) EXPECT_EQ(vola_test::voxel_set(d), vola_test::voxel_set(t.level_of_detail(depth)));
      }
  }
  EXPECT_THROW(vola::analysis::downsample(tree_of({}, 2), 3), vola::InvalidArgument);
}

}  // namespace
}  // namespace vola_analysis_test
