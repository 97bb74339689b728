// Reference payload words (nbits = 1): per voxel the last point's payload, per block
// the payload of the lexicographically greatest (x, y, z) voxel in it whose payload
// is not zero (FORMAT.md section 8), in sparse and dense files.
#include <algorithm>
#include <map>
#include <random>

#include <gtest/gtest.h>

#include "test_support.hpp"
#include "vola/builder.hpp"
#include "vola/file.hpp"

namespace vola_test {
namespace {

struct PayloadCase {
  int depth = 1;
  vola::PointCloud cloud;
  std::map<Xyz, std::uint64_t> last_payload;  // voxel -> payload of its last point
};

// Identity toolkit mapping: bbox [0, S-1]^3 and integer coordinates. A quarter of the
// payloads are zero (the case the reference's sparse writer mishandles).
PayloadCase make_case(std::uint64_t seed, int depth) {
  std::mt19937_64 rng(seed);
  PayloadCase c;
  c.depth = depth;
  const auto drawn = random_voxels(rng, depth, seed % 2 ? Shape::clustered : Shape::uniform, 1500);
  std::vector<Xyz> points = drawn;
  for (std::size_t i = 0; i < drawn.size() / 3; ++i) points.push_back(drawn[rng() % drawn.size()]);
  std::shuffle(points.begin(), points.end(), rng);
  for (const Xyz& p : points) {
    for (int a = 0; a < 3; ++a) c.cloud.xyz.push_back(p[a]);
    const std::uint64_t payload = rng() % 4 == 0 ? 0 : (rng() & 0x00FFFFFFFFFFFFFFull);
    c.cloud.payload.push_back(payload);
    c.last_payload[p] = payload;
  }
  return c;
}

vola::BuildOptions options_for(const PayloadCase& c) {
  const double last = vola::side_of(c.depth) - 1.0;
  return {.depth = c.depth, .bbox = vola::Box{{0, 0, 0}, {last, last, last}}, .payload = true};
}

// Block payload words of each level, blocks in storage order (FORMAT.md 8).
std::vector<std::vector<std::uint64_t>> slow_block_payloads(const std::map<Xyz, std::uint64_t>& voxels, int depth) {
  std::vector<std::vector<std::uint64_t>> levels;
  for (int level = 0; level < depth; ++level) {
    std::map<std::vector<unsigned>, std::pair<std::optional<Xyz>, std::uint64_t>> blocks;
    for (const auto& [v, payload] : voxels) {
      std::vector<unsigned> parent = slow_path(v, level, depth);
      parent.pop_back();
      auto& best = blocks[parent];
      if (payload != 0 && (!best.first || v > *best.first)) best = {v, payload};
    }
    std::vector<std::uint64_t> words;
    for (const auto& [path, best] : blocks) words.push_back(best.second);
    if (words.empty()) words.push_back(0);  // the root of an empty tree
    levels.push_back(words);
  }
  return levels;
}

// Dense payload words: per x-run word, the payload of the lexicographically greatest
// voxel with a non-zero payload whose level-L cell lies in the word.
std::vector<std::uint64_t> slow_dense_body(const std::map<Xyz, std::uint64_t>& voxels, int depth) {
  XyzSet set;
  for (const auto& [v, p] : voxels) set.insert(v);
  const auto occupancy = slow_dense_words(set, depth);
  std::vector<std::uint64_t> body;
  std::size_t at = 0;
  for (int level = 0; level < depth; ++level) {
    const std::size_t n = std::size_t{1} << (6 * level);
    body.insert(body.end(), occupancy.begin() + static_cast<std::ptrdiff_t>(at),
                occupancy.begin() + static_cast<std::ptrdiff_t>(at + n));
    at += n;
    std::vector<std::uint64_t> payload(n, 0);
    std::vector<std::optional<Xyz>> best(n);
    const std::uint64_t s = std::uint64_t{1} << (2 * (level + 1));
    for (const auto& [v, p] : voxels) {
      if (p == 0) continue;
      const Xyz c = coarse_cell(v, level, depth);
      const std::size_t w = static_cast<std::size_t>((c[0] + s * c[1] + s * s * c[2]) / 64);
      if (!best[w] || v > *best[w]) best[w] = v, payload[w] = p;
    }
    body.insert(body.end(), payload.begin(), payload.end());
  }
  return body;
}

class Payload : public ::testing::TestWithParam<int> {};  // depth

TEST_P(Payload, EveryVoxelKeepsItsLastPointsPayload) {
  const PayloadCase c = make_case(100 + GetParam(), GetParam());
  const vola::Tree tree = vola::build(c.cloud, options_for(c));
  ASSERT_EQ(voxel_set(tree).size(), c.last_payload.size());
  EXPECT_TRUE(tree.has_payload());
  EXPECT_EQ(tree.nbits(), 1u);
  ASSERT_EQ(tree.voxel_payloads().size(), tree.voxel_count());
  for (const auto& [v, payload] : c.last_payload) {
    ASSERT_EQ(tree.voxel_payload(to_voxel(v)), payload) << v[0] << " " << v[1] << " " << v[2];
    ASSERT_EQ(tree.voxel_payloads()[*tree.rank(to_voxel(v))], payload);
  }
}

TEST_P(Payload, BlockPayloadsFollowTheReferenceRule) {
  const PayloadCase c = make_case(200 + GetParam(), GetParam());
  const vola::Tree tree = vola::build(c.cloud, options_for(c));
  const auto expected = slow_block_payloads(c.last_payload, c.depth);
  for (int level = 0; level < c.depth; ++level) {
    const auto words = tree.payload(level);
    ASSERT_EQ(std::vector<std::uint64_t>(words.begin(), words.end()), expected[level]) << "level " << level;
  }
}

TEST_P(Payload, SparseFilesStoreBlockPayloadsOnly) {
  const PayloadCase c = make_case(300 + GetParam(), GetParam());
  const vola::Tree tree = vola::build(c.cloud, options_for(c));
  const auto bytes = vola::serialize(tree);
  EXPECT_EQ(get_le<std::uint32_t>(bytes, 8), 1u);  // nbits
  std::size_t blocks = 0;
  for (int level = 0; level < c.depth; ++level) blocks += tree.occupancy(level).size();
  EXPECT_EQ(bytes.size(), 80 + 16 * blocks);
  const vola::Tree back = vola::parse(bytes, "payload");
  EXPECT_TRUE(back.voxel_payloads().empty());
  // A voxel read from a sparse file has its leaf block's payload.
  const auto leaf = slow_block_payloads(c.last_payload, c.depth).back();
  std::size_t block = 0;
  tree.for_each_block(c.depth - 1, [&](std::size_t b, std::uint64_t word, std::uint32_t ox, std::uint32_t oy,
                                        std::uint32_t oz) {
    EXPECT_EQ(b, block++);
    while (word) {
      const unsigned bit = static_cast<unsigned>(std::countr_zero(word));
      word &= word - 1;
      const vola::Voxel v{ox + (bit & 3u), oy + ((bit >> 2) & 3u), oz + (bit >> 4)};
      ASSERT_EQ(back.block_payload(v), leaf[b]);
      ASSERT_EQ(back.voxel_payload(v), leaf[b]);
    }
  });
}

// Dense files hold 64^(D-1) leaf words: checked at the depths where that is small.
class DensePayload : public ::testing::TestWithParam<int> {};  // depth

TEST_P(DensePayload, FilesFollowTheReferenceRuleAndReadBackPerWord) {
  const PayloadCase c = make_case(400 + GetParam(), GetParam());
  const vola::Tree tree = vola::build(c.cloud, options_for(c));
  const auto bytes = vola::serialize(tree, {.layout = vola::Layout::dense});
  const auto expected = slow_dense_body(c.last_payload, c.depth);
  ASSERT_EQ(bytes.size(), 80 + 8 * expected.size());
  for (std::size_t i = 0; i < expected.size(); ++i)
    ASSERT_EQ(get_le<std::uint64_t>(bytes, 80 + 8 * i), expected[i]) << "word " << i;
  // Read back, each voxel gets the payload word of its leaf dense word.
  const vola::Tree back = vola::parse(bytes, "dense");
  const std::size_t leaf_payload = expected.size() - (std::size_t{1} << (6 * (c.depth - 1)));
  const std::uint64_t s = vola::side_of(c.depth);
  for (const auto& [v, p] : c.last_payload) {
    const std::size_t w = static_cast<std::size_t>((v[0] + s * v[1] + s * s * v[2]) / 64);
    ASSERT_EQ(back.voxel_payload(to_voxel(v)), expected[leaf_payload + w]);
  }
  // Written dense again, the same bytes: the coarse words are kept as read, since a
  // voxel's payload (its run's word) cannot give them back where some point's payload
  // is 0 (one in four here).
  EXPECT_EQ(vola::serialize(back, {.layout = vola::Layout::dense}), bytes);
  vola::Tree changed = back;
  changed.set_voxel_payloads(std::vector<std::uint64_t>(back.voxel_payloads().begin(), back.voxel_payloads().end()));
  EXPECT_TRUE(changed.dense_coarse_payloads().empty());  // new payloads: the coarse words follow them
}

INSTANTIATE_TEST_SUITE_P(Depths, Payload, ::testing::Values(1, 2, 3, 5, 8, 10),
                         [](const auto& test_param) { return "depth" + std::to_string(test_param.param); });
INSTANTIATE_TEST_SUITE_P(Depths, DensePayload, ::testing::Values(1, 2, 3),
                         [](const auto& test_param) { return "depth" + std::to_string(test_param.param); });

TEST(PayloadDefaults, CloudWithoutPayloadsGetsTheReferenceDefault) {
  vola::PointCloud cloud;
  cloud.xyz = {0, 0, 0, 15, 15, 15, 5, 6, 7};
  const vola::Tree tree = vola::build(cloud, {.depth = 2, .payload = true});
  EXPECT_EQ(vola::kDefaultPayload, 0x00FFFFFFFFFFFFFFull);  // FORMAT.md 8: 7 x 0xFF
  for (const vola::Voxel& v : {vola::Voxel{0, 0, 0}, vola::Voxel{15, 15, 15}})
    EXPECT_EQ(tree.voxel_payload(v), vola::kDefaultPayload);
  for (int level = 0; level < 2; ++level)
    for (std::uint64_t w : tree.payload(level)) EXPECT_EQ(w, vola::kDefaultPayload);
}

TEST(PayloadDefaults, TreesWithoutPayloadAnswerNothing) {
  vola::PointCloud cloud;
  cloud.xyz = {0, 0, 0, 3, 3, 3};
  cloud.payload = {5, 6};  // ignored without options.payload
  const vola::Tree tree = vola::build(cloud, {.depth = 1});
  EXPECT_FALSE(tree.has_payload());
  EXPECT_EQ(tree.nbits(), 0u);
  EXPECT_FALSE(tree.voxel_payload({0, 0, 0}).has_value());
  EXPECT_FALSE(tree.block_payload({0, 0, 0}).has_value());
  EXPECT_EQ(get_le<std::uint32_t>(vola::serialize(tree), 8), 0u);
}

TEST(PayloadDefaults, EmptyVoxelsHaveNoPayload) {
  vola::PointCloud cloud;
  cloud.xyz = {0, 0, 0, 15, 15, 15};
  cloud.payload = {1, 2};
  vola::Tree tree = vola::build(cloud, {.depth = 2, .payload = true});
  EXPECT_FALSE(tree.voxel_payload({1, 0, 0}).has_value());
  EXPECT_FALSE(tree.block_payload({1, 0, 0}).has_value());
  // Outside the 16^3 grid: (16, 0, 0) must not alias onto (0, 0, 0).
  EXPECT_FALSE(tree.voxel_payload({16, 0, 0}).has_value());
  EXPECT_FALSE(tree.block_payload({16, 0, 0}).has_value());
  EXPECT_THROW(tree.set_voxel_payloads({1, 2, 3}), vola::InvalidArgument);
}

}  // namespace
}  // namespace vola_test
