// The mutable VOLA-style brick index against a std::map, and its frozen tree against
// the same cells.
#include <gtest/gtest.h>

#include <map>
#include <random>

#include "test_support.hpp"
#include "vola/slam/brick_index.hpp"
#include "vola/slam/tsdf_store.hpp"

namespace {

using namespace vola::slam;

TEST(SlamBrickIndex, MatchesAMapUnderRandomInsertions) {
  for (int levels : {1, 2, 4, 6}) {
    std::mt19937_64 rng(static_cast<std::uint64_t>(levels));
    BrickIndex index(levels);
    std::map<std::array<std::uint32_t, 3>, std::uint32_t> reference;
    const std::uint32_t side = index.side();
    // Clustered cells (a surface-like blob) plus scattered ones.
    std::uniform_int_distribution<std::uint32_t> any(0, side - 1), near(0, std::min(side, 16u) - 1);
    for (int i = 0; i < 3000; ++i) {
      const bool cluster = i % 3 != 0;
      const std::array<std::uint32_t, 3> c = cluster ? std::array<std::uint32_t, 3>{near(rng), near(rng), near(rng)}
                                                     : std::array<std::uint32_t, 3>{any(rng), any(rng), any(rng)};
      if (reference.count(c)) {
        EXPECT_THROW(index.insert(c[0], c[1], c[2], 0), vola::InvalidArgument);
        continue;
      }
      const auto value = static_cast<std::uint32_t>(reference.size());
      index.insert(c[0], c[1], c[2], value);
      reference[c] = value;
    }
    EXPECT_EQ(index.size(), reference.size());
    for (int i = 0; i < 5000; ++i) {
      const std::array<std::uint32_t, 3> c{i % 2 ? near(rng) : any(rng), i % 2 ? near(rng) : any(rng), any(rng) % 16};
      const auto found = index.find(c[0], c[1], c[2]);
      const auto it = reference.find(c);
      ASSERT_EQ(found.has_value(), it != reference.end()) << levels;
      if (found) {
        EXPECT_EQ(*found, it->second);
      }
    }
    for (const auto& [c, v] : reference) ASSERT_EQ(index.find(c[0], c[1], c[2]), v);
    EXPECT_FALSE(index.find(side, 0, 0));
    EXPECT_THROW(index.insert(side, 0, 0, 1), vola::InvalidArgument);
    // Frozen: a vola::Tree with exactly these cells.
    const vola::Tree tree = index.to_tree();
    vola_test::XyzSet expected;
    for (const auto& [c, v] : reference) expected.insert({c[0], c[1], c[2]});
    EXPECT_EQ(vola_test::voxel_set(tree), expected);
  }
}

TEST(SlamBrickIndex, SparseStoreAllocatesOnceAndCountsItsMemory) {
  VolumeGeometry g;
  g.voxel_size = 0.01;
  g.bricks_per_side = 100;  // index of 4 levels (256), allocations limited to 100
  SparseTsdfStore store(g);
  EXPECT_EQ(store.brick({1, 2, 3}), nullptr);
  TsdfVoxel* b = store.allocate({1, 2, 3});
  b[5].weight = 2.0f;
  EXPECT_EQ(store.allocate({1, 2, 3}), b);
  EXPECT_EQ(store.brick({1, 2, 3})[5].weight, 2.0f);
  EXPECT_THROW(store.allocate({100, 0, 0}), vola::InvalidArgument);
  EXPECT_EQ(store.brick_count(), 1u);
  EXPECT_GE(store.memory_bytes(), kBrickVoxels * sizeof(TsdfVoxel));
  g.bricks_per_side = 12;
  DenseTsdfStore dense(g);
  EXPECT_EQ(dense.brick({1, 2, 3}), nullptr);  // untouched reads as absent, as in the sparse store
  dense.allocate({1, 2, 3});
  EXPECT_NE(dense.brick({1, 2, 3}), nullptr);
  EXPECT_EQ(dense.brick({12, 2, 3}), nullptr);
  EXPECT_GE(dense.memory_bytes(), std::size_t{12} * 12 * 12 * kBrickVoxels * sizeof(TsdfVoxel));
}

}  // namespace
