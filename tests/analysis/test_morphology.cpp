// Dilate, erode, fill, crop and downsample against brute-force twins on std::set models.
#include <gtest/gtest.h>

#include <map>
#include <string>
#include <utility>
#include <vector>

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

// A converted map's origin sits on its data's minimum: a clipped dilation lost the
// inflation below it. dilate_unclipped grows the grid where the voxels come within the
// radius of a face, and equals the model's dilation of the voxels moved onto that grid.
TEST(Morphology, DilateUnclippedGrowsTheGridInsteadOfCuttingAtItsFaces) {
  const XyzSet at_faces{{0, 0, 0}, {5, 6, 7}, {63, 63, 2}, {30, 0, 40}};  // depth 3: side 64
  vola::Tree t = tree_of(at_faces, 3);
  t.set_frame(vola::Frame{vola::Quantization::grid, {10, 20, 30}, 0.5});
  for (Element e : {Element::sphere, Element::cube})
    for (int r : {1, 2, 3}) {
      SCOPED_TRACE((e == Element::cube ? "cube r" : "sphere r") + std::to_string(r));
      const vola::Tree out = vola::analysis::dilate_unclipped(t, r, e);
      const auto u = static_cast<std::uint32_t>(r);
      XyzSet moved;  // every axis has a voxel at 0: the origin moves down by r on each
      for (const Xyz& v : at_faces) moved.insert({v[0] + u, v[1] + u, v[2] + u});
      EXPECT_EQ(out.depth(), 4);  // 63 + 2r needs more than 64 cells
      EXPECT_EQ(vola_test::voxel_set(out), model_dilate(moved, 4, r, e));
      const vola::Frame f = out.frame();
      EXPECT_EQ(f.quantization, vola::Quantization::grid);
      EXPECT_EQ(f.origin, (vola::Point{10 - 0.5 * r, 20 - 0.5 * r, 30 - 0.5 * r}));
      EXPECT_EQ(f.voxel_size, 0.5);
      EXPECT_GT(out.voxel_count(), vola::analysis::dilate(t, r, e).voxel_count());
    }
  // Voxels clear of every face: the grid stays, and the result is dilate's.
  const XyzSet inside{{10, 10, 10}, {40, 41, 42}};
  const vola::Tree clear = tree_of(inside, 3);
  const vola::Tree same = vola::analysis::dilate_unclipped(clear, 3, Element::sphere);
  EXPECT_EQ(same.depth(), 3);
  EXPECT_EQ(vola_test::voxel_set(same), model_dilate(inside, 3, 3, Element::sphere));
  // A grid that would need more than depth 10 is refused, naming the way out.
  EXPECT_THROW(vola::analysis::dilate_unclipped(tree_of({{1048575, 5, 5}}, 10), 3, Element::cube),
               vola::InvalidArgument);
}

// Solid boxes straddling block edges of every level (the walk gathers each block's
// neighbours from the level above) and touching the grid's edges, at radii that need
// one brick of halo, several cube steps (radius > 4) or wider windows (sphere radius
// > 4: two or more bricks of halo; > 16: two blocks of halo on the level above).
TEST(Morphology, DilateAndErodeAcrossBlockEdgesAndLargeRadii) {
  auto box = [](XyzSet& s, std::uint32_t x, std::uint32_t y, std::uint32_t z, std::uint32_t side) {
    for (std::uint32_t k = 0; k < side; ++k)
      for (std::uint32_t j = 0; j < side; ++j)
        for (std::uint32_t i = 0; i < side; ++i) s.insert({x + i, y + j, z + k});
  };
  XyzSet edges;  // depth 5: side 1024
  box(edges, 253, 254, 252, 6);  // across x = y = z = 256, the root's cell edge
  box(edges, 510, 509, 511, 5);  // across 512
  box(edges, 62, 63, 61, 4);     // across 64
  box(edges, 0, 0, 0, 5);        // the grid's low corner
  box(edges, 1019, 1019, 1018, 5);  // and the high one
  edges.insert({13, 400, 1023});
  edges.insert({767, 768, 3});
  for (Element e : {Element::cube, Element::sphere})
    for (int r : {1, 2, 3, 4, 5, 6}) {
      if (e == Element::cube && r == 6) continue;  // the model is slow there
      SCOPED_TRACE((e == Element::cube ? "edges cube r" : "edges sphere r") + std::to_string(r));
      const vola::Tree t = tree_of(edges, 5);
      EXPECT_EQ(vola_test::voxel_set(vola::analysis::dilate(t, r, e)), model_dilate(edges, 5, r, e));
      EXPECT_EQ(vola_test::voxel_set(vola::analysis::erode(t, r, e)), model_erode(edges, 5, r, e));
    }
  std::mt19937_64 rng(11);
  XyzSet few;  // depth 4: side 256
  std::uniform_int_distribution<std::uint32_t> any(0, 255);
  for (int i = 0; i < 30; ++i) few.insert({any(rng), any(rng), any(rng)});
  box(few, 60, 61, 62, 12);  // 1728 voxels: erosion by up to 5 keeps some
  XyzSet sparse;             // the same without the box, for the largest radii
  for (const Xyz& v : few)
    if (!(v[0] >= 60 && v[0] < 72 && v[1] >= 61 && v[1] < 73 && v[2] >= 62 && v[2] < 74)) sparse.insert(v);
  for (Element e : {Element::cube, Element::sphere})
    for (int r : {9, 13, 17}) {
      SCOPED_TRACE((e == Element::cube ? "sparse cube r" : "sparse sphere r") + std::to_string(r));
      const vola::Tree t = tree_of(sparse, 4);
      EXPECT_EQ(vola_test::voxel_set(vola::analysis::dilate(t, r, e)), model_dilate(sparse, 4, r, e));
      EXPECT_EQ(vola_test::voxel_set(vola::analysis::erode(t, r, e)), model_erode(sparse, 4, r, e));
    }
  for (Element e : {Element::cube, Element::sphere})
    for (int r : {4, 5}) {
      SCOPED_TRACE((e == Element::cube ? "box cube r" : "box sphere r") + std::to_string(r));
      const vola::Tree t = tree_of(few, 4);
      EXPECT_EQ(vola_test::voxel_set(vola::analysis::erode(t, r, e)), model_erode(few, 4, r, e));
    }
}

// Small grids at every radius the grid allows: at depth 1 the root is the only brick,
// at depth 2 the root's window is the only one above the bricks.
TEST(Morphology, EveryRadiusOnSmallGrids) {
  std::mt19937_64 rng(12);
  for (int depth : {1, 2}) {
    const int side = static_cast<int>(vola::side_of(depth));
    for (double p : {0.0, 0.01, 0.3, 1.0}) {
      const XyzSet voxels = bernoulli(rng, depth, p);
      const vola::Tree t = tree_of(voxels, depth);
      for (Element e : {Element::cube, Element::sphere})
        for (int r = 0; r < side; ++r) {
          if ((p >= 0.3 && r > 3) || (r > 7 && r % 3 != 0)) continue;  // the model is slow there
          std::string trace = e == Element::cube ? "cube" : "sphere";
          trace += " d" + std::to_string(depth) + " p" + std::to_string(p) + " r" + std::to_string(r);
          SCOPED_TRACE(trace);
          EXPECT_EQ(vola_test::voxel_set(vola::analysis::dilate(t, r, e)), model_dilate(voxels, depth, r, e));
          EXPECT_EQ(vola_test::voxel_set(vola::analysis::erode(t, r, e)), model_erode(voxels, depth, r, e));
        }
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

// Cost follows the data, not the radius: an element that fits nowhere erodes to nothing at
// once (three voxels across a depth-10 grid at radius 5000 took 2.9 GB and failed), and a
// dilation no machine could hold is refused before the walk (a cube of radius 10^6 ran
// for minutes).
TEST(Morphology, HugeRadiiAreAnsweredOrRefusedAtOnce) {
  const vola::Tree t = tree_of({{0, 0, 0}, {500000, 500000, 500000}, {1048575, 1048575, 1048575}}, 10);
  for (const Element e : {Element::sphere, Element::cube}) {
    const vola::Tree eroded = vola::analysis::erode(t, 5000, e);
    EXPECT_TRUE(eroded.empty());
    EXPECT_EQ(eroded.depth(), 10);
    try {
      vola::analysis::dilate(t, 1048575, e);
      ADD_FAILURE() << "a dilation of 2^60 voxels was attempted";
    } catch (const vola::InvalidArgument& error) {
      EXPECT_NE(std::string(error.what()).find("the dilation would hold at least"), std::string::npos) << error.what();
    }
  }
  // A 5^3 cube of voxels erodes by radius 2 to its centre, by 3 to nothing (the shortcut and
  // the walk agree).
  XyzSet cube;
  for (std::uint32_t x = 10; x < 15; ++x)
    for (std::uint32_t y = 10; y < 15; ++y)
      for (std::uint32_t z = 10; z < 15; ++z) cube.insert({x, y, z});
  const vola::Tree c = tree_of(cube, 3);
  EXPECT_EQ(vola::analysis::erode(c, 2, Element::cube).voxel_count(), 1u);
  EXPECT_TRUE(vola::analysis::erode(c, 3, Element::cube).empty());
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
  // Corners swapped on one axis: refused (an empty file was written, exit 0).
  const vola::Tree t = tree_of({{1, 1, 1}}, 2);
  EXPECT_THROW(vola::analysis::crop(t, {0, 5, 0}, {3, 2, 3}), vola::InvalidArgument);
  EXPECT_EQ(vola::analysis::crop(t, {2, 2, 2}, {2, 2, 2}).voxel_count(), 0u);  // a box of one empty voxel
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
        if (min_voxels == 1) {
          EXPECT_EQ(vola_test::voxel_set(d), vola_test::voxel_set(t.level_of_detail(depth)));
        }
      }
  }
  EXPECT_THROW(vola::analysis::downsample(tree_of({}, 2), 3), vola::InvalidArgument);
}

}  // namespace
TEST(Morphology, ProgressRisesToTheWholeAndLeavesTheResultAlone) {
  XyzSet lattice;  // 8000 voxels 32 apart: 8000 blocks above the leaves, reported every 64
  for (std::uint32_t z = 0; z < 20; ++z)
    for (std::uint32_t y = 0; y < 20; ++y)
      for (std::uint32_t x = 0; x < 20; ++x) lattice.insert({32 * x + 5, 32 * y + 7, 32 * z + 9});
  const vola::Tree t = tree_of(lattice, 5);
  for (const Element e : {Element::sphere, Element::cube}) {
    for (const bool grow : {true, false}) {
      SCOPED_TRACE(std::string(grow ? "dilate " : "erode ") + (e == Element::sphere ? "sphere" : "cube"));
      std::vector<std::pair<std::uint64_t, std::uint64_t>> heard;
      const auto listen = [&](std::uint64_t done, std::uint64_t total) { heard.emplace_back(done, total); };
      const int radius = e == Element::cube ? 6 : 1;  // the cube in two passes
      const vola::Tree with = grow ? vola::analysis::dilate(t, radius, e, listen) : vola::analysis::erode(t, radius, e, listen);
      const vola::Tree without = grow ? vola::analysis::dilate(t, radius, e) : vola::analysis::erode(t, radius, e);
      EXPECT_EQ(vola_test::voxel_set(with), vola_test::voxel_set(without));
      ASSERT_GE(heard.size(), e == Element::cube && grow ? 2u : 1u);
      EXPECT_EQ(heard.back().first, heard.back().second);  // the whole, at the end
      for (std::size_t i = 0; i < heard.size(); ++i) {
        EXPECT_EQ(heard[i].second, heard[0].second);
        EXPECT_LE(heard[i].first, heard[i].second);
        if (i > 0) {
          EXPECT_GE(heard[i].first, heard[i - 1].first);
        }
      }
    }
  }
}

}  // namespace vola_analysis_test
