// Tree queries against a slow reference (a std::set of voxels, and a dense bit grid
// for small depths): random voxel sets of every depth 1..10 and several shapes.
#include <algorithm>
#include <random>

#include <gtest/gtest.h>

#include "test_support.hpp"
#include "vola/builder.hpp"
#include "vola/tree.hpp"

namespace vola_test {
namespace {

constexpr int kRepeats = 3;  // scenarios per (shape, depth)

vola::Tree build_tree(const Scenario& s) {
  std::vector<vola::Voxel> input;
  for (const Xyz& v : s.voxels) input.push_back(to_voxel(v));
  return vola::build_from_voxels(input, s.depth);
}

std::vector<vola::Key> sorted_keys(const XyzSet& voxels) {
  std::vector<vola::Key> keys;
  for (const Xyz& v : voxels) keys.push_back(vola::encode(v[0], v[1], v[2]));
  std::sort(keys.begin(), keys.end());
  return keys;
}

// Voxels next to occupied ones (mostly empty, in occupied blocks: the hard cases)
// plus uniformly random ones.
std::vector<Xyz> probe_voxels(const XyzSet& voxels, int depth, std::mt19937_64& rng) {
  const std::uint32_t last = vola::side_of(depth) - 1;
  std::vector<Xyz> probes;
  for (int i = 0; i < 1000; ++i) probes.push_back(random_xyz(rng, depth));
  int n = 0;
  for (const Xyz& v : voxels) {
    if (++n > 1000) break;
    for (int a = 0; a < 3; ++a) {
      Xyz up = v, down = v;
      if (up[a] < last) ++up[a];
      if (down[a] > 0) --down[a];
      probes.push_back(up);
      probes.push_back(down);
    }
  }
  return probes;
}

class TreeProperty : public ::testing::TestWithParam<Shape> {
 protected:
  template <class Check>
  void for_each_scenario(Check check) {
    for (std::uint64_t seed : seeds_for(GetParam(), kRepeats)) {
      const Scenario s = make_scenario(seed);
      SCOPED_TRACE(s.describe());
      check(s, s.unique(), build_tree(s));
      if (HasFatalFailure()) return;
    }
  }
};

TEST_P(TreeProperty, WordsEqualTheReferenceSparseLayout) {
  for_each_scenario([](const Scenario& s, const XyzSet& voxels, const vola::Tree& tree) {
    EXPECT_EQ(tree.depth(), s.depth);
    EXPECT_EQ(tree.side(), vola::side_of(s.depth));
    EXPECT_EQ(tree.voxel_count(), voxels.size());
    EXPECT_EQ(tree.empty(), voxels.empty());
    EXPECT_FALSE(tree.has_payload());
    const auto expected = slow_sparse_words(voxels, s.depth);
    const auto words = tree.words();
    ASSERT_EQ(std::vector<std::uint64_t>(words.begin(), words.end()), expected);
    // Levels are consecutive slices of words().
    std::size_t at = 0;
    for (int level = 0; level < s.depth; ++level) {
      const auto occupancy = tree.occupancy(level);
      ASSERT_EQ(occupancy.data(), words.data() + at) << "level " << level;
      at += occupancy.size();
      EXPECT_TRUE(tree.payload(level).empty());
    }
    EXPECT_EQ(at, words.size());
  });
}

TEST_P(TreeProperty, BuildFromKeysAndFromSortedKeysGiveTheSameWords) {
  for_each_scenario([](const Scenario& s, const XyzSet& voxels, const vola::Tree& tree) {
    std::vector<vola::Key> keys;  // input order, duplicates kept
    for (const Xyz& v : s.voxels) keys.push_back(vola::encode(v[0], v[1], v[2]));
    const vola::Tree from_keys = vola::build_from_keys(keys, s.depth);
    const auto unique_sorted = sorted_keys(voxels);
    const vola::Tree from_sorted = vola::build_from_sorted_keys(unique_sorted, s.depth);
    const auto w = tree.words();
    const auto wk = from_keys.words();
    const auto ws = from_sorted.words();
    EXPECT_TRUE(std::equal(w.begin(), w.end(), wk.begin(), wk.end()));
    EXPECT_TRUE(std::equal(w.begin(), w.end(), ws.begin(), ws.end()));
  });
}

TEST_P(TreeProperty, ContainsIsTrueExactlyForOccupiedVoxels) {
  std::mt19937_64 rng(11);
  for_each_scenario([&](const Scenario& s, const XyzSet& voxels, const vola::Tree& tree) {
    for (const Xyz& v : voxels) ASSERT_TRUE(tree.contains(v[0], v[1], v[2]));
    for (const Xyz& v : probe_voxels(voxels, s.depth, rng))
      ASSERT_EQ(tree.contains(to_voxel(v)), voxels.count(v) == 1) << v[0] << " " << v[1] << " " << v[2];
    if (s.depth <= 3) {
      // Every cell of the grid against a dense bit grid.
      const std::uint32_t side = vola::side_of(s.depth);
      std::vector<bool> grid(std::size_t{side} * side * side, false);
      for (const Xyz& v : voxels) grid[v[0] + side * (v[1] + std::size_t{side} * v[2])] = true;
      for (std::uint32_t z = 0; z < side; ++z)
        for (std::uint32_t y = 0; y < side; ++y)
          for (std::uint32_t x = 0; x < side; ++x)
            ASSERT_EQ(tree.contains(x, y, z), grid[x + side * (y + std::size_t{side} * z)])
                << x << " " << y << " " << z;
    }
  });
}

TEST_P(TreeProperty, ContainsIsFalseOutsideTheGrid) {
  // Coordinates past the side must not alias onto voxels inside the grid.
  for_each_scenario([](const Scenario& s, const XyzSet& voxels, const vola::Tree& tree) {
    const std::uint32_t side = vola::side_of(s.depth);
    int n = 0;
    for (const Xyz& v : voxels) {
      if (++n > 200) break;
      // side << 2 at depth 10 is 2^22: past the 20 bits per axis a key holds.
      for (std::uint32_t offset : {side, 2 * side, side << 2}) {
        EXPECT_FALSE(tree.contains(v[0] + offset, v[1], v[2]));
        EXPECT_FALSE(tree.contains(v[0], v[1] + offset, v[2]));
        EXPECT_FALSE(tree.contains(v[0], v[1], v[2] + offset));
        EXPECT_FALSE(tree.rank(vola::Voxel{v[0], v[1], v[2] + offset}).has_value());
        const Xyz cell = coarse_cell(v, 0, s.depth);
        EXPECT_FALSE(tree.contains_node(0, vola::Voxel{cell[0] + 4, cell[1], cell[2]}));
      }
    }
  });
}

TEST_P(TreeProperty, RankIsTheIndexInKeyOrder) {
  std::mt19937_64 rng(12);
  for_each_scenario([&](const Scenario& s, const XyzSet& voxels, const vola::Tree& tree) {
    const auto keys = sorted_keys(voxels);
    for (std::size_t i = 0; i < keys.size(); ++i) {
      const auto r = tree.rank(vola::decode(keys[i]));
      ASSERT_TRUE(r.has_value());
      ASSERT_EQ(*r, i);
    }
    for (const Xyz& v : probe_voxels(voxels, s.depth, rng)) {
      if (!voxels.count(v)) {
        ASSERT_FALSE(tree.rank(to_voxel(v)).has_value());
      }
    }
  });
}

TEST_P(TreeProperty, ForEachVoxelAndKeysFollowTheSortedKeys) {
  for_each_scenario([](const Scenario& s, const XyzSet& voxels, const vola::Tree& tree) {
    const auto expected = sorted_keys(voxels);
    EXPECT_EQ(tree.keys(), expected);
    std::vector<vola::Key> visited;
    tree.for_each_voxel([&](const vola::Voxel& v) { visited.push_back(vola::encode(v)); });
    EXPECT_EQ(visited, expected);
    EXPECT_EQ(voxel_sequence(tree), slow_storage_order(voxels, s.depth));
  });
}

TEST_P(TreeProperty, NodesOfEveryLevelAreTheCoarseCells) {
  std::mt19937_64 rng(13);
  for_each_scenario([&](const Scenario& s, const XyzSet& voxels, const vola::Tree& tree) {
    for (int level = 0; level < s.depth; ++level) {
      SCOPED_TRACE("level " + std::to_string(level));
      const XyzSet cells = slow_cells(voxels, level, s.depth);
      EXPECT_EQ(tree.node_count(level), cells.size());
      for (const Xyz& c : cells) ASSERT_TRUE(tree.contains_node(level, to_voxel(c)));
      for (int i = 0; i < 300; ++i) {
        const Xyz c = random_xyz(rng, level + 1);
        ASSERT_EQ(tree.contains_node(level, to_voxel(c)), cells.count(c) == 1);
      }
      std::vector<Xyz> visited;
      tree.for_each_node(level, [&](const vola::Voxel& c) { visited.push_back(to_xyz(c)); });
      EXPECT_EQ(visited, slow_storage_order(cells, level + 1));
    }
  });
}

TEST_P(TreeProperty, BlocksAreVisitedInStorageOrderWithTheirOrigins) {
  for_each_scenario([](const Scenario& s, const XyzSet&, const vola::Tree& tree) {
    for (int level = 0; level < s.depth; ++level) {
      std::size_t expected_block = 0;
      tree.for_each_block(level, [&](std::size_t block, std::uint64_t word, std::uint32_t ox, std::uint32_t oy,
                                     std::uint32_t oz) {
        EXPECT_EQ(block, expected_block++);
        EXPECT_EQ(word, tree.occupancy(level)[block]);
        EXPECT_EQ(ox % 4 + oy % 4 + oz % 4, 0u);
        // The block's cells are occupied exactly where its word has bits.
        for (unsigned b = 0; b < 64; ++b) {
          const vola::Voxel c{ox + (b & 3u), oy + ((b >> 2) & 3u), oz + (b >> 4)};
          ASSERT_EQ(tree.contains_node(level, c), ((word >> b) & 1u) == 1u);
        }
      });
      EXPECT_EQ(expected_block, tree.empty() ? 0 : tree.occupancy(level).size());
    }
  });
}

TEST_P(TreeProperty, LevelOfDetailHoldsTheCoarseCells) {
  for_each_scenario([](const Scenario& s, const XyzSet& voxels, const vola::Tree& tree) {
    for (int depth = 1; depth <= s.depth; ++depth) {
      const vola::Tree coarse = tree.level_of_detail(depth);
      EXPECT_EQ(coarse.depth(), depth);
      EXPECT_EQ(voxel_set(coarse), slow_cells(voxels, depth - 1, s.depth)) << "lod depth " << depth;
      const auto expected = slow_sparse_words(slow_cells(voxels, depth - 1, s.depth), depth);
      const auto w = coarse.words();
      EXPECT_EQ(std::vector<std::uint64_t>(w.begin(), w.end()), expected);
    }
    EXPECT_THROW((void)tree.level_of_detail(0), vola::InvalidArgument);
    EXPECT_THROW((void)tree.level_of_detail(s.depth + 1), vola::InvalidArgument);
  });
}

INSTANTIATE_TEST_SUITE_P(Shapes, TreeProperty, ::testing::ValuesIn(kAllShapes),
                         [](const auto& test_param) { return std::string(shape_name(test_param.param)); });

TEST(Tree, DefaultTreeIsEmptyDepthOne) {
  const vola::Tree tree;
  EXPECT_EQ(tree.depth(), 1);
  EXPECT_TRUE(tree.empty());
  EXPECT_EQ(tree.words().size(), 1u);
  EXPECT_EQ(tree.words()[0], 0u);
  EXPECT_FALSE(tree.contains(0, 0, 0));
  EXPECT_TRUE(tree.keys().empty());
}

TEST(Tree, LevelOfDetailGrowsTheVoxelSizeByFourPerLevel) {
  const std::vector<vola::Voxel> voxels = {{0, 0, 0}, {63, 63, 63}};
  const vola::Tree tree = vola::build_from_voxels(voxels, 3);
  const vola::Frame fine = tree.frame();
  const vola::Frame coarse = tree.level_of_detail(1).frame();
  EXPECT_DOUBLE_EQ(coarse.voxel_size, fine.voxel_size * 16);
  EXPECT_EQ(coarse.quantization, vola::Quantization::grid);
}

TEST(Tree, FromLevelsChecksTheLevelSizes) {
  // Root with bits 0 and 1: level 1 must have two non-zero words.
  EXPECT_NO_THROW(vola::Tree::from_levels(2, false, {0b11, 1, 1}));
  EXPECT_THROW(vola::Tree::from_levels(2, false, {0b11, 1}), vola::FormatError);
  EXPECT_THROW(vola::Tree::from_levels(2, false, {0b11, 1, 0}), vola::FormatError);
  EXPECT_THROW(vola::Tree::from_levels(2, false, {0b11, 1, 1, 1}), vola::FormatError);
  EXPECT_THROW(vola::Tree::from_levels(0, false, {0}), vola::InvalidArgument);
  EXPECT_THROW(vola::Tree::from_levels(11, false, {0}), vola::InvalidArgument);
}

}  // namespace
}  // namespace vola_test
