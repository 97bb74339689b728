// unite / intersect / subtract against std::set_union / set_intersection /
// set_difference on voxel sets.
#include <algorithm>
#include <array>
#include <cmath>
#include <iterator>
#include <random>
#include <set>

#include <gtest/gtest.h>

#include "test_support.hpp"
#include "vola/builder.hpp"
#include "vola/setops.hpp"

namespace vola_test {
namespace {

vola::Tree tree_of(const XyzSet& voxels, int depth) {
  std::vector<vola::Voxel> input;
  for (const Xyz& v : voxels) input.push_back(to_voxel(v));
  return vola::build_from_voxels(input, depth);
}

template <class Op>
XyzSet reference(const XyzSet& a, const XyzSet& b, Op op) {
  XyzSet out;
  op(a.begin(), a.end(), b.begin(), b.end(), std::inserter(out, out.end()));
  return out;
}

class SetOps : public ::testing::TestWithParam<Shape> {};

TEST_P(SetOps, MatchTheStdSetAlgorithms) {
  for (std::uint64_t seed : seeds_for(GetParam(), 2)) {
    const Scenario s = make_scenario(seed);
    SCOPED_TRACE(s.describe());
    // The second operand overlaps the first: half of its voxels are the first's.
    std::mt19937_64 rng(seed + 77);
    const XyzSet a = s.unique();
    XyzSet b;
    for (const Xyz& v : a)
      if (rng() % 2) b.insert(v);
    const auto extra = random_voxels(rng, s.depth, static_cast<Shape>(rng() % 6), 1 + rng() % 2000);
    b.insert(extra.begin(), extra.end());

    const vola::Tree ta = tree_of(a, s.depth), tb = tree_of(b, s.depth);
    const auto uni = [](auto... x) { return std::set_union(x...); };
    const auto inter = [](auto... x) { return std::set_intersection(x...); };
    const auto diff = [](auto... x) { return std::set_difference(x...); };

    const vola::Tree u = vola::unite(ta, tb);
    const vola::Tree i = vola::intersect(ta, tb);
    const vola::Tree d = vola::subtract(ta, tb);
    const vola::Tree d2 = vola::subtract(tb, ta);
    EXPECT_EQ(voxel_set(u), reference(a, b, uni));
    EXPECT_EQ(voxel_set(i), reference(a, b, inter));
    EXPECT_EQ(voxel_set(d), reference(a, b, diff));
    EXPECT_EQ(voxel_set(d2), reference(b, a, diff));
    // The results are well-formed trees: their words are the reference layout.
    for (const vola::Tree* t : {&u, &i, &d, &d2}) {
      EXPECT_EQ(t->depth(), s.depth);
      const auto w = t->words();
      EXPECT_EQ(std::vector<std::uint64_t>(w.begin(), w.end()), slow_sparse_words(voxel_set(*t), s.depth));
    }
    // With an empty operand.
    const vola::Tree none = tree_of({}, s.depth);
    EXPECT_EQ(voxel_set(vola::unite(ta, none)), a);
    EXPECT_TRUE(vola::intersect(ta, none).empty());
    EXPECT_EQ(voxel_set(vola::subtract(ta, none)), a);
    EXPECT_TRUE(vola::subtract(ta, ta).empty());
  }
}

INSTANTIATE_TEST_SUITE_P(Shapes, SetOps, ::testing::ValuesIn(kAllShapes),
                         [](const auto& test_param) { return std::string(shape_name(test_param.param)); });

TEST(SetOpsArguments, DifferentDepthsAreRefused) {
  const vola::Tree a = tree_of({{1, 1, 1}}, 2), b = tree_of({{1, 1, 1}}, 3);
  EXPECT_THROW(vola::unite(a, b), vola::InvalidArgument);
  EXPECT_THROW(vola::intersect(a, b), vola::InvalidArgument);
  EXPECT_THROW(vola::subtract(a, b, vola::FrameCheck::ignore), vola::InvalidArgument);
}

TEST(SetOpsArguments, DifferentGridsAreRefusedUnlessIgnored) {
  vola::PointCloud cloud;
  cloud.xyz = {0.5, 0.5, 0.5, 2.5, 2.5, 2.5};
  const vola::Tree a = vola::build(cloud, {.quantization = vola::Quantization::grid, .depth = 2, .voxel_size = 1.0,
                                           .origin = vola::Point{0, 0, 0}});
  const vola::Tree b = vola::build(cloud, {.quantization = vola::Quantization::grid, .depth = 2, .voxel_size = 1.0,
                                           .origin = vola::Point{-0.6, 0, 0}});
  const vola::Tree c = vola::build(cloud, {.quantization = vola::Quantization::grid, .depth = 2, .voxel_size = 2.0,
                                           .origin = vola::Point{0, 0, 0}});
  EXPECT_THROW(vola::unite(a, b), vola::InvalidArgument);
  EXPECT_THROW(vola::intersect(a, c), vola::InvalidArgument);
  const vola::Tree u = vola::unite(a, b, vola::FrameCheck::ignore);
  EXPECT_EQ(voxel_set(u), (XyzSet{{0, 0, 0}, {2, 2, 2}, {1, 0, 0}, {3, 2, 2}}));
  // The result keeps the first tree's grid and georeferencing.
  ASSERT_TRUE(u.stored_frame().has_value());
  EXPECT_EQ(*u.stored_frame(), *a.stored_frame());
  EXPECT_EQ(u.georef(), a.georef());
  // Equal grids combine without FrameCheck::ignore.
  EXPECT_EQ(voxel_set(vola::intersect(a, a)), voxel_set(a));
}

// Grids of one voxel size whose origins differ by whole voxels are one lattice (maps of
// separate `vola map` runs: each origin follows its data): combined in world space, on
// the lower origin and a depth that holds both. Held to sets of voxel corners in world
// coordinates, computed here from each tree's own frame.
TEST(SetOpsArguments, GridsOnOneLatticeCombineInWorldSpace) {
  using Corner = std::array<long long, 3>;  // a voxel's lower corner in whole metres
  const auto corners = [](const vola::Tree& t) {
    std::set<Corner> out;
    const vola::Frame f = *t.stored_frame();
    t.for_each_voxel([&](const vola::Voxel& v) {
      out.insert({std::llround(f.origin[0] + v.x * f.voxel_size), std::llround(f.origin[1] + v.y * f.voxel_size),
                  std::llround(f.origin[2] + v.z * f.voxel_size)});
    });
    return out;
  };
  vola::PointCloud first, second;
  first.xyz = {0.5, 0.5, 0.5, 2.5, 2.5, 2.5, 7.5, 1.5, 0.5};
  second.xyz = {2.5, 2.5, 2.5, -3.5, 4.5, 1.5, 20.5, 0.5, 9.5};
  const vola::Tree a = vola::build(
      first, {.quantization = vola::Quantization::grid, .depth = 2, .voxel_size = 1.0, .origin = vola::Point{0, 0, 0}});
  const vola::Tree b = vola::build(
      second,
      {.quantization = vola::Quantization::grid, .depth = 3, .voxel_size = 1.0, .origin = vola::Point{-4, 0, -1}});
  const std::set<Corner> ca = corners(a), cb = corners(b);
  std::set<Corner> both, either, only_a;
  std::set_union(ca.begin(), ca.end(), cb.begin(), cb.end(), std::inserter(either, either.end()));
  std::set_intersection(ca.begin(), ca.end(), cb.begin(), cb.end(), std::inserter(both, both.end()));
  std::set_difference(ca.begin(), ca.end(), cb.begin(), cb.end(), std::inserter(only_a, only_a.end()));
  ASSERT_EQ(both.size(), 1u);  // (2, 2, 2) lies in both
  const vola::Tree u = vola::unite(a, b), i = vola::intersect(a, b), d = vola::subtract(a, b);
  EXPECT_EQ(corners(u), either);
  EXPECT_EQ(corners(i), both);
  EXPECT_EQ(corners(d), only_a);
  EXPECT_EQ(u.stored_frame()->origin, (vola::Point{-4, 0, -1}));  // the lower origin on each axis
  EXPECT_EQ(u.depth(), 3);                                        // what holds x from -4 to 20
  EXPECT_EQ(corners(vola::unite(b, a)), either);
  // Half a voxel apart is not one lattice: refused as before.
  const vola::Tree half = vola::build(
      second,
      {.quantization = vola::Quantization::grid, .depth = 3, .voxel_size = 1.0, .origin = vola::Point{-4.5, 0, -1}});
  EXPECT_THROW(vola::unite(a, half), vola::InvalidArgument);
}

}  // namespace
}  // namespace vola_test
