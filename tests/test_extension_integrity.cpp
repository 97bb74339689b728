// A .vol's extension (frame, CRS WKT, attributes) cannot be lost or altered silently:
// the header's mode bit says it follows the levels, and its trailer holds its length and
// a CRC-32C. Cutting or corrupting it is a FormatError; files written before (version-1
// extensions without the bit or the trailer) still read.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "test_support.hpp"
#include "vola/builder.hpp"
#include "vola/error.hpp"
#include "vola/file.hpp"

namespace vola_test {
namespace {

using ::testing::HasSubstr;

// A grid-mode tree with a CRS and an attribute: every record kind of a version-1 file.
vola::Tree rich_tree() {
  vola::PointCloud cloud;
  cloud.xyz = {0.5, 0.5, 0.5, 9.5, 3.5, 1.5, 2.5, 7.5, 4.5};
  cloud.attributes.push_back({"intensity", vola::ValueType::u16, vola::Reduction::max, {100, 200, 300}});
  vola::Tree tree = vola::build(
      cloud, {.quantization = vola::Quantization::grid, .depth = 2, .voxel_size = 1.0, .origin = vola::Point{}});
  tree.georef().crs_wkt = "PROJCRS[\"a CRS\"]";
  return tree;
}

std::uint64_t levels_end(const vola::Tree& tree) { return 80 + 8 * tree.words().size(); }

vola::FormatError error_of(const std::vector<std::uint8_t>& bytes) {
  const auto error = format_error_of([&] { (void)vola::parse(bytes, "t.vol"); });
  if (!error) throw std::runtime_error("no FormatError");
  return *error;
}

TEST(ExtensionIntegrity, AFileCutAtTheEndOfItsLevelsIsRefused) {
  const vola::Tree tree = rich_tree();
  auto bytes = vola::serialize(tree);
  EXPECT_EQ(bytes[6] & 0x80, 0x80);  // the mode byte's extension bit
  bytes.resize(levels_end(tree));
  const auto e = error_of(bytes);
  EXPECT_EQ(e.offset(), levels_end(tree));
  EXPECT_THAT(e.cause(), HasSubstr("the file is cut"));
}

TEST(ExtensionIntegrity, EveryCutInsideTheExtensionIsRefused) {
  const vola::Tree tree = rich_tree();
  const auto bytes = vola::serialize(tree);
  for (std::size_t size = levels_end(tree) + 1; size < bytes.size(); ++size) {
    SCOPED_TRACE(size);
    EXPECT_THROW((void)vola::parse(std::vector<std::uint8_t>(bytes.begin(), bytes.begin() + static_cast<std::ptrdiff_t>(size))),
                 vola::FormatError);
  }
}

TEST(ExtensionIntegrity, AFlippedBitAnywhereInTheExtensionIsRefused) {
  const vola::Tree tree = rich_tree();
  const auto bytes = vola::serialize(tree);
  const std::uint64_t trailer = bytes.size() - 16;
  for (std::size_t at = levels_end(tree); at < bytes.size(); ++at) {
    SCOPED_TRACE(at);
    auto bad = bytes;
    bad[at] ^= 0x10;
    EXPECT_THROW((void)vola::parse(bad), vola::FormatError);
  }
  // A changed attribute value keeps every record well-formed: only the checksum sees it.
  const vola::Tree back = vola::parse(bytes);
  ASSERT_EQ(back.attributes().size(), 1u);
  auto bad = bytes;
  bad[trailer - 8] ^= 0x01;  // within the padded attribute data, the last record
  const auto e = error_of(bad);
  EXPECT_EQ(e.offset(), trailer + 8);
  EXPECT_THAT(e.cause(), HasSubstr("the extension is corrupt"));
}

TEST(ExtensionIntegrity, FilesWrittenBeforeTheChecksumStillRead) {
  const vola::Tree tree = rich_tree();
  auto bytes = vola::serialize(tree);
  // As written before: no mode bit, version 1, no trailer.
  bytes[6] &= 0x7F;
  const std::uint64_t at = levels_end(tree);
  put_le<std::uint32_t>(bytes, at + 8, 1);
  bytes.resize(bytes.size() - 16);
  vola::FileLayout layout;
  const vola::Tree back = vola::parse(bytes, "old.vol", &layout);
  EXPECT_EQ(layout.extension_version, 1u);
  EXPECT_EQ(back.georef().crs_wkt, tree.georef().crs_wkt);
  EXPECT_EQ(back.stored_frame(), tree.stored_frame());
  ASSERT_EQ(back.attributes().size(), 1u);
  EXPECT_EQ(back.attributes().columns()[0].get(0), tree.attributes().columns()[0].get(0));
}

TEST(ExtensionIntegrity, ReferenceFilesCarryNeitherBitNorExtension) {
  const std::vector<vola::Voxel> voxels = {{1, 2, 3}, {4, 5, 6}};
  const vola::Tree tree = vola::build_from_voxels(voxels, 2);
  const auto bytes = vola::serialize(tree);
  EXPECT_EQ(bytes[6], 0);
  EXPECT_EQ(bytes.size(), levels_end(tree));
}

}  // namespace
}  // namespace vola_test
