// Census and change counts against direct counts over std::set models.
#include <gtest/gtest.h>

#include <cmath>

#include <map>
#include <numeric>

#include "analysis_models.hpp"
#include "vola/analysis/census.hpp"
#include "vola/analysis/change.hpp"

namespace vola_analysis_test {
namespace {

TEST(Census, LevelsColumnsHeightsAndRegions) {
  for (const Grid& g : random_grids(7)) {
    SCOPED_TRACE(g.name);
    vola::Tree t = tree_of(g.voxels, g.depth);
    t.set_frame({vola::Quantization::grid, {10, 20, 30}, 0.5});
    vola::analysis::CensusOptions options;
    options.bins = 7;
    options.regions.push_back({"box", vola::Box{{10, 20, 30}, {14, 22, 40}}, {}});
    options.regions.push_back({"triangle", std::nullopt, {{{10, 20}}, {{20, 20}}, {{10, 30}}}});
    const auto c = vola::analysis::take_census(t, options);
    EXPECT_EQ(c.voxels, g.voxels.size());
    ASSERT_EQ(c.levels.size(), static_cast<std::size_t>(g.depth));
    for (int l = 0; l < g.depth; ++l) {
      const auto cells = vola_test::slow_cells(g.voxels, l, g.depth);
      EXPECT_EQ(c.levels[l].cells, cells.size());
      const auto parents = l ? vola_test::slow_cells(g.voxels, l - 1, g.depth).size() : 1u;
      EXPECT_EQ(c.levels[l].blocks, g.voxels.empty() && l ? 0u : parents);
    }
    std::set<std::pair<std::uint32_t, std::uint32_t>> columns;
    std::uint64_t in_box = 0, in_triangle = 0;
    for (const Xyz& v : g.voxels) {
      columns.insert({v[0], v[1]});
      const double x = 10 + 0.5 * (v[0] + 0.5), y = 20 + 0.5 * (v[1] + 0.5), z = 30 + 0.5 * (v[2] + 0.5);
      in_box += x <= 14 && y <= 22 && z <= 40;
      in_triangle += (x - 10) + (y - 20) < 10;  // centres never lie on the hypotenuse
    }
    EXPECT_EQ(c.columns, columns.size());
    ASSERT_TRUE(c.voxel_size);
    EXPECT_DOUBLE_EQ(c.volume(), static_cast<double>(g.voxels.size()) * 0.125);
    EXPECT_DOUBLE_EQ(c.footprint_area(), static_cast<double>(columns.size()) * 0.25);
    EXPECT_EQ(c.region_voxels, (std::vector<std::uint64_t>{in_box, in_triangle}));
    EXPECT_EQ(std::accumulate(c.heights.counts.begin(), c.heights.counts.end(), std::uint64_t{0}), g.voxels.size());
  }
}

TEST(Census, ClassificationCountsAndNames) {
  vola::Tree t = tree_of({{0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {3, 3, 3}}, 1);
  vola::AttributeColumn cls("classification", vola::ValueType::u8, vola::Reduction::majority, 4);
  const int codes[] = {2, 6, 2, 5};
  for (std::size_t i = 0; i < 4; ++i) cls.set(i, codes[i]);
  t.attributes().add(std::move(cls));
  const auto c = vola::analysis::take_census(t);
  ASSERT_EQ(c.attributes.size(), 1u);
  const auto& a = c.attributes[0];
  ASSERT_EQ(a.classes.size(), 3u);
  EXPECT_EQ(a.classes[0].code, 2);
  EXPECT_EQ(a.classes[0].voxels, 2u);
  EXPECT_EQ(a.classes[2].code, 6);
  EXPECT_EQ(vola::analysis::asprs_class_name(6), "Building");
  EXPECT_EQ(vola::analysis::asprs_class_name(2), "Ground");
  EXPECT_EQ(vola::analysis::asprs_class_name(40), "Reserved");
  EXPECT_DOUBLE_EQ(a.mean, 15.0 / 4);
  EXPECT_FALSE(c.voxel_size);  // no GIS grid recorded
}

// A voxel whose value is NaN (none of its points had one: a LAS no_data) has no value:
// left out of the count, the mean and the histogram, counted apart.
TEST(Census, VoxelsWithoutAValueAreLeftOutOfTheFigures) {
  vola::Tree t = tree_of({{0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {3, 3, 3}}, 1);
  vola::AttributeColumn deviation("deviation", vola::ValueType::f64, vola::Reduction::mean, 4);
  const double values[] = {1.0, std::nan(""), 3.0, 5.0};
  for (std::size_t i = 0; i < 4; ++i) deviation.set(i, values[i]);
  t.attributes().add(std::move(deviation));
  vola::AttributeColumn none("none", vola::ValueType::f64, vola::Reduction::mean, 4);
  for (std::size_t i = 0; i < 4; ++i) none.set(i, std::nan(""));
  t.attributes().add(std::move(none));
  vola::analysis::CensusOptions options;
  options.bins = 4;
  const auto c = vola::analysis::take_census(t, options);
  const auto& a = c.attributes[0];
  EXPECT_EQ(a.count, 3u);
  EXPECT_EQ(a.without_value, 1u);
  EXPECT_DOUBLE_EQ(a.mean, 3.0);
  EXPECT_EQ(a.histogram.counts, (std::vector<std::uint64_t>{1, 0, 1, 1}));  // numpy.histogram of 1, 3, 5
  EXPECT_EQ(a.histogram.min, 1.0);
  EXPECT_EQ(a.histogram.max, 5.0);
  const auto& b = c.attributes[1];
  EXPECT_EQ(b.count, 0u);
  EXPECT_EQ(b.without_value, 4u);
  EXPECT_EQ(b.histogram.counts, (std::vector<std::uint64_t>(4, 0)));
  EXPECT_EQ(b.histogram.min, 0.0);
}

TEST(Change, CountsMatchTheSets) {
  std::mt19937_64 rng(8);
  for (int depth : {1, 2, 3}) {
    const XyzSet a = bernoulli(rng, depth, 0.3), b = bernoulli(rng, depth, 0.3);
    std::uint64_t both = 0;
    for (const Xyz& v : a) both += b.count(v);
    const auto c = vola::analysis::count_changes(tree_of(a, depth), tree_of(b, depth));
    EXPECT_EQ(c.unchanged, both);
    EXPECT_EQ(c.removed, a.size() - both);
    EXPECT_EQ(c.added, b.size() - both);
  }
  EXPECT_THROW(vola::analysis::count_changes(tree_of({}, 1), tree_of({}, 2)), vola::InvalidArgument);
}

}  // namespace
}  // namespace vola_analysis_test
