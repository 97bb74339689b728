// serialize -> parse and write -> read/open_mapped on random trees: sparse, dense
// (depth <= 4, checked against a slow dense encoder) and compressed.
#include <random>

#include <gtest/gtest.h>

#include "test_support.hpp"
#include "vola/builder.hpp"
#include "vola/file.hpp"

namespace vola_test {
namespace test_file_roundtrip {
namespace {

vola::Tree build_tree(const Scenario& s) {
  std::vector<vola::Voxel> input;
  for (const Xyz& v : s.voxels) input.push_back(to_voxel(v));
  return vola::build_from_voxels(input, s.depth);
}

std::vector<std::uint64_t> words_of(const vola::Tree& tree) {
  return {tree.words().begin(), tree.words().end()};
}

std::vector<std::uint64_t> body_words(const std::vector<std::uint8_t>& bytes) {
  std::vector<std::uint64_t> words((bytes.size() - 80) / 8);
  for (std::size_t i = 0; i < words.size(); ++i) words[i] = get_le<std::uint64_t>(bytes, 80 + 8 * i);
  return words;
}

class FileRoundTrip : public ::testing::TestWithParam<Shape> {
 protected:
  template <class Check>
  void for_each_scenario(Check check) {
    for (std::uint64_t seed : seeds_for(GetParam(), 2)) {
      const Scenario s = make_scenario(seed);
      SCOPED_TRACE(s.describe());
      check(s, s.unique(), build_tree(s));
      if (HasFatalFailure()) return;
    }
  }
};

TEST_P(FileRoundTrip, SparseBytesAreHeaderPlusWordsAndParseBack) {
  for_each_scenario([](const Scenario& s, const XyzSet& voxels, const vola::Tree& tree) {
    const auto bytes = vola::serialize(tree);
    ASSERT_EQ(bytes.size(), 80 + 8 * tree.words().size());  // no extension
    EXPECT_EQ(get_le<std::uint32_t>(bytes, 0), 80u);
    EXPECT_EQ(get_le<std::uint16_t>(bytes, 4), 1u);
    EXPECT_EQ(bytes[6], 0u);
    EXPECT_EQ(bytes[7], s.depth);
    EXPECT_EQ(get_le<std::uint32_t>(bytes, 8), 0u);
    EXPECT_EQ(body_words(bytes), slow_sparse_words(voxels, s.depth));

    vola::FileLayout layout;
    const vola::Tree back = vola::parse(bytes, "roundtrip", &layout);
    EXPECT_EQ(back.depth(), s.depth);
    EXPECT_EQ(words_of(back), words_of(tree));
    EXPECT_EQ(voxel_set(back), voxels);
    EXPECT_FALSE(back.is_mapped());
    EXPECT_EQ(layout.file_size, bytes.size());
    EXPECT_EQ(layout.level_bytes, bytes.size() - 80);
    EXPECT_EQ(layout.extension_offset, 0u);
    EXPECT_FALSE(layout.compressed_levels);
    EXPECT_EQ(vola::serialize(back), bytes);
  });
}

TEST_P(FileRoundTrip, DenseBytesFollowTheFlatBitmapLayout) {
  for_each_scenario([](const Scenario& s, const XyzSet& voxels, const vola::Tree& tree) {
    if (s.depth > 4) return;  // 64^(D-1) leaf words: the reference's dense files stop being practical
    const auto bytes = vola::serialize(tree, {.layout = vola::Layout::dense});
    EXPECT_EQ(bytes[6], 1u);
    const auto expected = slow_dense_words(voxels, s.depth);
    ASSERT_EQ(bytes.size(), 80 + 8 * expected.size());
    EXPECT_EQ(body_words(bytes), expected);

    const vola::Tree back = vola::parse(bytes, "dense");
    EXPECT_EQ(voxel_set(back), voxels);
    EXPECT_EQ(words_of(back), words_of(tree));  // decoded into the sparse layout
    if (s.depth == 1) {
      // FORMAT.md 5: depth-1 dense and sparse files differ only in the mode byte.
      auto sparse = vola::serialize(tree);
      sparse[6] = 1;
      EXPECT_EQ(sparse, bytes);
    }
  });
}

TEST_P(FileRoundTrip, CompressedFilesParseBackWhenZstdIsAvailable) {
  for_each_scenario([](const Scenario& s, const XyzSet& voxels, const vola::Tree& tree) {
    if (!vola::compression_available()) {
      EXPECT_THROW(vola::serialize(tree, {.compress = true}), vola::Error);
      return;
    }
    const auto bytes = vola::serialize(tree, {.compress = true});
    EXPECT_EQ(get_le<std::uint16_t>(bytes, 4), vola::kVersionCompressed);
    vola::FileLayout layout;
    const vola::Tree back = vola::parse(bytes, "compressed", &layout);
    EXPECT_TRUE(layout.compressed_levels);
    EXPECT_EQ(layout.extension_offset, 80u);
    EXPECT_EQ(back.depth(), s.depth);
    EXPECT_EQ(words_of(back), words_of(tree));
    EXPECT_EQ(voxel_set(back), voxels);
  });
}

TEST_P(FileRoundTrip, WrittenFilesMapWithTheSameAnswers) {
  TempDir dir;
  std::mt19937_64 rng(21);
  for_each_scenario([&](const Scenario& s, const XyzSet& voxels, const vola::Tree& tree) {
    const auto path = (dir / ("t" + std::to_string(s.seed) + ".vol")).string();
    vola::write(tree, path);
    EXPECT_FALSE(fs::exists(path + ".part"));
    EXPECT_EQ(read_bytes(path), vola::serialize(tree));

    const vola::Tree read = vola::read(path);
    EXPECT_FALSE(read.is_mapped());
    vola::Tree mapped = vola::open_mapped(path);
    EXPECT_TRUE(mapped.is_mapped());
    // The tree keeps the mapping alive: the name may go away.
    fs::remove(path);
    EXPECT_EQ(words_of(mapped), words_of(tree));
    EXPECT_EQ(voxel_sequence(mapped), voxel_sequence(tree));
    std::uint64_t i = 0;
    for (const Xyz& v : voxel_sequence(tree)) ASSERT_EQ(mapped.rank(to_voxel(v)), i++);
    for (int k = 0; k < 500; ++k) {
      const Xyz v = random_xyz(rng, s.depth);
      ASSERT_EQ(mapped.contains(to_voxel(v)), voxels.count(v) == 1);
    }
    for (int level = 0; level < s.depth; ++level) EXPECT_EQ(mapped.node_count(level), tree.node_count(level));
    // A level of detail of a mapped tree views the same mapping.
    EXPECT_TRUE(mapped.level_of_detail(1).is_mapped());
  });
}

TEST_P(FileRoundTrip, MappedDenseAndCompressedFilesAreDecodedIntoMemory) {
  TempDir dir;
  for_each_scenario([&](const Scenario& s, const XyzSet& voxels, const vola::Tree& tree) {
    if (s.depth > 3) return;
    const auto dense = (dir / "d.dvol").string();
    vola::write(tree, dense, {.layout = vola::Layout::dense});
    const vola::Tree d = vola::open_mapped(dense);
    EXPECT_FALSE(d.is_mapped());
    EXPECT_EQ(voxel_set(d), voxels);
    if (vola::compression_available()) {
      const auto packed = (dir / "c.vol").string();
      vola::write(tree, packed, {.compress = true});
      const vola::Tree c = vola::open_mapped(packed);
      EXPECT_FALSE(c.is_mapped());
      EXPECT_EQ(voxel_set(c), voxels);
    }
  });
}

INSTANTIATE_TEST_SUITE_P(Shapes, FileRoundTrip, ::testing::ValuesIn(kAllShapes),
                         [](const auto& test_param) { return std::string(shape_name(test_param.param)); });

TEST(FileWrite, DenseBeyondTheLimitIsRefused) {
  const std::vector<vola::Voxel> one = {{1, 2, 3}};
  const vola::Tree tree = vola::build_from_voxels(one, 6);
  EXPECT_THROW(vola::serialize(tree, {.layout = vola::Layout::dense}), vola::InvalidArgument);
  EXPECT_THROW(vola::serialize(tree, {.layout = vola::Layout::dense, .compress = true}), vola::InvalidArgument);
}

TEST(FileWrite, WriteIntoAMissingFolderThrowsIoErrorAndLeavesNothing) {
  TempDir dir;
  const vola::Tree tree;
  const auto path = (dir / "no" / "such" / "x.vol").string();
  EXPECT_THROW(vola::write(tree, path), vola::IoError);
  EXPECT_FALSE(fs::exists(path));
}

TEST(FileRead, MissingFileThrowsIoError) {
  EXPECT_THROW(vola::read("/nonexistent/vola/file.vol"), vola::IoError);
  EXPECT_THROW(vola::open_mapped("/nonexistent/vola/file.vol"), vola::IoError);
}

TEST(FileRead, HeaderFieldsComeBack) {
  std::vector<vola::Voxel> voxels = {{1, 2, 3}, {4, 5, 6}};
  vola::Tree tree = vola::build_from_voxels(voxels, 2);
  tree.georef().epsg = 29902;
  tree.georef().lat = 53.3457;
  tree.georef().lon = -6.2673;
  tree.georef().bbox = {{-1.5, 2.25, 3.0}, {10.0, 20.5, 30.125}};
  const auto bytes = vola::serialize(tree);
  EXPECT_EQ(get_le<std::uint32_t>(bytes, 12), 29902u);
  EXPECT_EQ(get_le<double>(bytes, 16), 53.3457);
  EXPECT_EQ(get_le<double>(bytes, 24), -6.2673);
  EXPECT_EQ(get_le<double>(bytes, 32), -1.5);
  EXPECT_EQ(get_le<double>(bytes, 72), 30.125);
  const vola::Tree back = vola::parse(bytes);
  EXPECT_EQ(back.georef(), tree.georef());
  const vola::Header h = vola::decode_header(bytes, "x");
  EXPECT_EQ(h.depth, 2);
  EXPECT_EQ(h.epsg, 29902u);
  EXPECT_EQ(h.bbox, tree.georef().bbox);
}

}  // namespace
}  // namespace test_file_roundtrip
}  // namespace vola_test
