// Connected components against breadth-first search over a std::set model.
#include <gtest/gtest.h>

#include <algorithm>
#include <map>

#include "analysis_models.hpp"
#include "vola/analysis/components.hpp"

namespace vola_analysis_test {
namespace {

using vola::analysis::Connectivity;

void expect_same_partition(const Grid& g, int connectivity) {
  SCOPED_TRACE(g.name + " connectivity " + std::to_string(connectivity));
  const vola::Tree tree = tree_of(g.voxels, g.depth);
  const auto result = vola::analysis::label_components(tree, vola::analysis::parse_connectivity(connectivity));
  const auto model = model_components(g.voxels, connectivity);
  ASSERT_EQ(result.label.size(), g.voxels.size());

  // A bijection between our labels and the model's.
  std::map<std::uint32_t, int> ours_to_model;
  std::map<int, std::uint32_t> model_to_ours;
  std::map<std::uint32_t, std::vector<Xyz>> members;
  std::size_t rank = 0;
  tree.for_each_voxel([&](const vola::Voxel& v) {
    const Xyz x = vola_test::to_xyz(v);
    const std::uint32_t ours = result.label[rank++];
    const int theirs = model.at(x);
    const auto [a, new_a] = ours_to_model.emplace(ours, theirs);
    const auto [b, new_b] = model_to_ours.emplace(theirs, ours);
    EXPECT_EQ(a->second, theirs);
    EXPECT_EQ(b->second, ours);
    members[ours].push_back(x);
  });
  ASSERT_EQ(result.components.size(), model_to_ours.size());

  // Sizes, boxes, centroids; order: largest first, ties by first voxel in key order.
  for (std::uint32_t id = 0; id < result.components.size(); ++id) {
    const auto& c = result.components[id];
    const auto& m = members[id];
    ASSERT_EQ(c.voxels, m.size());
    Xyz lo = m[0], hi = m[0];
    std::array<double, 3> sum{0, 0, 0};
    for (const Xyz& v : m)
      for (int a = 0; a < 3; ++a) {
        lo[a] = std::min(lo[a], v[a]);
        hi[a] = std::max(hi[a], v[a]);
        sum[a] += v[a];
      }
    EXPECT_EQ(vola_test::to_xyz(c.min), lo);
    EXPECT_EQ(vola_test::to_xyz(c.max), hi);
    for (int a = 0; a < 3; ++a) EXPECT_NEAR(c.centroid[a], sum[a] / static_cast<double>(m.size()), 1e-9);
    EXPECT_EQ(vola::encode(vola_test::to_voxel(m[0])), tree.keys()[c.first_rank]);
    if (id > 0) {
      const auto& prev = result.components[id - 1];
      EXPECT_TRUE(prev.voxels > c.voxels || (prev.voxels == c.voxels && prev.first_rank < c.first_rank));
    }
  }
}

TEST(Components, MatchBreadthFirstSearchOnRandomGrids) {
  for (std::uint64_t seed : {1u, 2u})
    for (const Grid& g : random_grids(seed))
      for (int c : {6, 18, 26}) expect_same_partition(g, c);
}

TEST(Components, ConnectivityTellsFacesEdgesAndCorners) {
  // Two voxels touching by a corner, two by an edge, one alone.
  const XyzSet v{{0, 0, 0}, {1, 1, 1}, {5, 5, 5}, {6, 6, 5}, {10, 0, 0}};
  const vola::Tree t = tree_of(v, 2);
  EXPECT_EQ(vola::analysis::label_components(t, Connectivity::faces).components.size(), 5u);
  EXPECT_EQ(vola::analysis::label_components(t, Connectivity::edges).components.size(), 4u);
  EXPECT_EQ(vola::analysis::label_components(t, Connectivity::corners).components.size(), 3u);
}

TEST(Components, EmptyTreeAndBadConnectivity) {
  EXPECT_TRUE(vola::analysis::label_components(tree_of({}, 3), Connectivity::corners).components.empty());
  EXPECT_THROW(vola::analysis::parse_connectivity(8), vola::InvalidArgument);
}

TEST(Components, SpanBlocksAcrossADeepGrid) {
  // A line along each axis crossing many 4x4x4 blocks at depth 8 is one component.
  XyzSet v;
  for (std::uint32_t i = 0; i < 200; ++i) {
    v.insert({1000 + i, 7, 9});
    v.insert({1199, 7 + i, 9});
    v.insert({1199, 206, 9 + i});
  }
  const auto r = vola::analysis::label_components(tree_of(v, 8), Connectivity::faces);
  ASSERT_EQ(r.components.size(), 1u);
  EXPECT_EQ(r.components[0].voxels, v.size());
}

}  // namespace
}  // namespace vola_analysis_test
