// Keys: encode/decode, digit(), node_at() against the per-level formula of FORMAT.md
// section 3, and key order == the order a sparse file stores voxels.
#include <algorithm>
#include <random>

#include <gtest/gtest.h>

#include "test_support.hpp"
#include "vola/key.hpp"

namespace vola_test {
namespace {

constexpr int kSamplesPerDepth = 3000;

class KeyAtDepth : public ::testing::TestWithParam<int> {};

TEST_P(KeyAtDepth, EncodeDecodeRoundTripsRandomCoordinates) {
  const int depth = GetParam();
  std::mt19937_64 rng(1000 + depth);
  const std::uint32_t last = vola::side_of(depth) - 1;
  std::vector<Xyz> samples = {{0, 0, 0}, {last, last, last}, {last, 0, 0}, {0, last, 0}, {0, 0, last}};
  for (int i = 0; i < kSamplesPerDepth; ++i) samples.push_back(random_xyz(rng, depth));
  for (const Xyz& v : samples) {
    const vola::Key key = vola::encode(v[0], v[1], v[2]);
    EXPECT_EQ(to_xyz(vola::decode(key)), v);
    EXPECT_EQ(vola::encode(to_voxel(v)), key);
    // A depth-D key uses 6*D bits.
    EXPECT_LT(key, vola::Key{1} << (6 * depth)) << v[0] << " " << v[1] << " " << v[2];
  }
}

TEST_P(KeyAtDepth, DigitIsTheLocalIndexOfEveryLevel) {
  const int depth = GetParam();
  std::mt19937_64 rng(2000 + depth);
  for (int i = 0; i < kSamplesPerDepth; ++i) {
    const Xyz v = random_xyz(rng, depth);
    const vola::Key key = vola::encode(v[0], v[1], v[2]);
    for (int level = 0; level < depth; ++level)
      ASSERT_EQ(vola::digit(key, level, depth), slow_local_index(v, level, depth))
          << "voxel " << v[0] << " " << v[1] << " " << v[2] << " level " << level;
  }
}

TEST_P(KeyAtDepth, NodeAtIsTheKeyOfTheCoarseCell) {
  const int depth = GetParam();
  std::mt19937_64 rng(3000 + depth);
  for (int i = 0; i < kSamplesPerDepth; ++i) {
    const Xyz v = random_xyz(rng, depth);
    const vola::Key key = vola::encode(v[0], v[1], v[2]);
    for (int level = 0; level < depth; ++level) {
      // node_at = the digits i_0..i_level read as a base-64 number.
      vola::Key from_path = 0;
      for (unsigned d : slow_path(v, level, depth)) from_path = from_path * 64 + d;
      const vola::Key node = vola::node_at(key, level, depth);
      ASSERT_EQ(node, from_path) << "level " << level;
      // ... which is the key of the level-`level` cell in a depth-(level+1) tree.
      const Xyz cell = coarse_cell(v, level, depth);
      ASSERT_EQ(node, vola::encode(cell[0], cell[1], cell[2]));
      ASSERT_EQ(vola::digit(key, level, depth), vola::digit(node, level, level + 1));
    }
    EXPECT_EQ(vola::node_at(key, depth - 1, depth), key);
  }
}

TEST_P(KeyAtDepth, KeyOrderIsPathOrder) {
  // Sorting by key must give the breadth-first block order of FORMAT.md section 4,
  // i.e. lexicographic order of the paths (i_0, ..., i_{D-1}).
  const int depth = GetParam();
  std::mt19937_64 rng(4000 + depth);
  for (int i = 0; i < kSamplesPerDepth; ++i) {
    const Xyz a = random_xyz(rng, depth);
    // Half of the pairs share a prefix, so deep digits decide too.
    Xyz b = random_xyz(rng, depth);
    if (i % 2) {
      const int shift = 2 * static_cast<int>(rng() % depth);
      for (int k = 0; k < 3; ++k) b[k] = ((a[k] >> shift) << shift) | (b[k] & ((1u << shift) - 1));
    }
    const bool key_less = vola::encode(a[0], a[1], a[2]) < vola::encode(b[0], b[1], b[2]);
    const bool path_less = slow_path(a, depth - 1, depth) < slow_path(b, depth - 1, depth);
    ASSERT_EQ(key_less, path_less) << a[0] << " " << a[1] << " " << a[2] << " vs " << b[0] << " " << b[1] << " "
                                   << b[2];
  }
}

TEST_P(KeyAtDepth, SortedKeysAreTheStorageOrderOfABuiltTree) {
  const int depth = GetParam();
  std::mt19937_64 rng(5000 + depth);
  const auto drawn = random_voxels(rng, depth, Shape::uniform, 2000);
  const XyzSet voxels(drawn.begin(), drawn.end());
  std::vector<vola::Key> keys;
  for (const Xyz& v : voxels) keys.push_back(vola::encode(v[0], v[1], v[2]));
  std::sort(keys.begin(), keys.end());
  std::vector<Xyz> by_key;
  for (vola::Key k : keys) by_key.push_back(to_xyz(vola::decode(k)));

  EXPECT_EQ(by_key, slow_storage_order(voxels, depth));
  std::vector<vola::Voxel> input;
  for (const Xyz& v : drawn) input.push_back(to_voxel(v));
  EXPECT_EQ(voxel_sequence(vola::build_from_voxels(input, depth)), by_key);
}

INSTANTIATE_TEST_SUITE_P(Depths, KeyAtDepth, ::testing::Range(vola::kMinDepth, vola::kMaxDepth + 1),
                         [](const auto& test_param) { return "depth" + std::to_string(test_param.param); });

TEST(Key, BitIndexIsXPlus4YPlus16Z) {
  for (unsigned z = 0; z < 4; ++z)
    for (unsigned y = 0; y < 4; ++y)
      for (unsigned x = 0; x < 4; ++x) EXPECT_EQ(vola::bit_index(x, y, z), x + 4 * y + 16 * z);
}

TEST(Key, SideIsFourToTheDepth) {
  std::uint64_t side = 1;
  for (int depth = vola::kMinDepth; depth <= vola::kMaxDepth; ++depth) {
    side *= 4;
    EXPECT_EQ(vola::side_of(depth), side);
  }
}

TEST(Key, EveryVoxelOfADepth2GridHasADistinctKey) {
  std::set<vola::Key> seen;
  for (std::uint32_t z = 0; z < 16; ++z)
    for (std::uint32_t y = 0; y < 16; ++y)
      for (std::uint32_t x = 0; x < 16; ++x) {
        const vola::Key k = vola::encode(x, y, z);
        EXPECT_LT(k, vola::Key{4096});
        seen.insert(k);
      }
  EXPECT_EQ(seen.size(), 4096u);
}

}  // namespace
}  // namespace vola_test
