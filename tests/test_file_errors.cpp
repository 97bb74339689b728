// Malformed files: each must throw vola::FormatError naming the right byte offset
// and cause, through parse(), read() and open_mapped() alike.
#include <chrono>
#include <limits>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "allocation_probe.hpp"
#include "test_support.hpp"
#include "vola/builder.hpp"
#include "vola/file.hpp"

namespace vola_test {
namespace {

using ::testing::HasSubstr;
using ::testing::StartsWith;

// Every entry point must report the same error.
void expect_format_error(const std::vector<std::uint8_t>& bytes, std::uint64_t offset, const std::string& phrase) {
  TempDir dir;
  const std::string path = (dir / "bad.vol").string();
  write_bytes(path, bytes);
  struct Reader {
    const char* what;
    std::function<void()> run;
  };
  const Reader readers[] = {
      {"parse", [&] { (void)vola::parse(bytes, "bad.vol"); }},
      {"read", [&] { (void)vola::read(path); }},
      {"open_mapped", [&] { (void)vola::open_mapped(path); }},
  };
  for (const auto& reader : readers) {
    SCOPED_TRACE(reader.what);
    const auto error = format_error_of(reader.run);
    ASSERT_TRUE(error.has_value()) << "no FormatError";
    ASSERT_TRUE(error->offset().has_value());
    EXPECT_EQ(*error->offset(), offset) << error->what();
    EXPECT_THAT(error->cause(), HasSubstr(phrase));
    const std::string name = std::string(reader.what) == "parse" ? "bad.vol" : path;
    EXPECT_EQ(error->file(), name);
    EXPECT_EQ(std::string(error->what()), name + ": byte " + std::to_string(offset) + ": " + error->cause());
  }
}

RawHeader header(int depth, int mode = 0, std::uint32_t nbits = 0) {
  RawHeader h;
  h.depth = static_cast<std::uint8_t>(depth);
  h.mode = static_cast<std::uint8_t>(mode);
  h.nbits = nbits;
  return h;
}

// A valid depth-2 sparse file: root bits 0 and 63, one voxel under each.
const std::vector<std::uint64_t> kValidDepth2 = {1 | (1ull << 63), 1ull << 5, 1ull << 42};

// Grid-mode trees always carry the extension (their frame).
std::vector<std::uint8_t> file_with_extension(std::uint64_t& extension_offset) {
  vola::PointCloud cloud;
  cloud.xyz = {0.5, 0.5, 0.5, 9.5, 3.5, 1.5};
  const vola::Tree tree = vola::build(
      cloud, {.quantization = vola::Quantization::grid, .depth = 2, .voxel_size = 1.0, .origin = vola::Point{}});
  extension_offset = 80 + 8 * tree.words().size();
  return vola::serialize(tree);
}

TEST(FileErrors, ValidInputsOfTheseTestsParse) {
  // The corrupt files below are derived from these: they must be fine to start with.
  EXPECT_NO_THROW(vola::parse(raw_file(header(2), kValidDepth2)));
  std::uint64_t at = 0;
  const auto bytes = file_with_extension(at);
  vola::FileLayout layout;
  EXPECT_NO_THROW(vola::parse(bytes, "x", &layout));
  EXPECT_EQ(layout.extension_offset, at);
}

TEST(FileErrors, EmptyFile) { expect_format_error({}, 0, "the file is 0 bytes, shorter than the 80-byte header"); }

TEST(FileErrors, ShorterThanTheHeader) {
  auto bytes = raw_file(header(1), {});
  bytes.resize(79);
  expect_format_error(bytes, 79, "the file is 79 bytes, shorter than the 80-byte header");
}

TEST(FileErrors, HeaderSizeIsNot80) {
  RawHeader h = header(1);
  h.header_size = 88;
  expect_format_error(raw_file(h, {0}), 0, "header size 88 is not the 80");
}

// Other formats' files are named for what they are, with what to do instead ("header
// size 1179861324 is not the 80 this format knows" was a LAS file).
TEST(FileErrors, OtherFormatsAreNamed) {
  const auto bytes_of = [](std::string_view text) {
    std::vector<std::uint8_t> b(text.begin(), text.end());
    b.resize(std::max<std::size_t>(b.size(), 200), 0);
    return b;
  };
  expect_format_error(bytes_of("LASF"), 0, "not a .vol file: a LAS/LAZ point file: `vola convert` makes voxels");
  expect_format_error(bytes_of("\x1f\x8b\x08"), 0, "not a .vol file: gzip-compressed: gunzip it first");
  expect_format_error(bytes_of("ply\nformat ascii 1.0\n"), 0, "not a .vol file: a PLY file");
  expect_format_error(bytes_of("\x93NUMPY"), 0, "not a .vol file: a NumPy array");
  expect_format_error(bytes_of(std::string_view("II*\0", 4)), 0, "not a .vol file: a TIFF");
  // A tile index given to collide, components, coords, export or sonify.
  expect_format_error(bytes_of("{\n\"type\": \"FeatureCollection\",\n\"vola\": { \"format\": \"vola-tile-index\""), 0,
                      "not a .vol file: a vola tile index: this command takes one .vol file");
  expect_format_error(bytes_of("  {\"type\": \"Feature\"}"), 0, "not a .vol file: JSON text");
  // Text: a README or an XYZ file (its header size read 1870012451).
  const std::string xyz = "1.5 2.25 3\n4 5 6\n7 8 9\n10 11 12\n13 14 15\n16 17 18\n19 20 21\n";
  expect_format_error(std::vector<std::uint8_t>(xyz.begin(), xyz.end()), 0, "not a .vol file: text (a point file");
  // Short ones too: the signature comes before the header's length.
  expect_format_error({'L', 'A', 'S', 'F', 1, 2}, 0, "a LAS/LAZ point file");
}

TEST(FileErrors, UnknownVersion) {
  RawHeader h = header(1);
  h.version = 3;
  expect_format_error(raw_file(h, {0}), 4, "version 3 is not known");
  h.version = 0;
  expect_format_error(raw_file(h, {0}), 4, "version 0 is not known");
}

TEST(FileErrors, ModeTwo) { expect_format_error(raw_file(header(1, 2), {0}), 6, "mode 2 is neither 0 (sparse) nor 1 (dense)"); }

TEST(FileErrors, DepthZero) { expect_format_error(raw_file(header(0), {0}), 7, "depth 0 is outside 1..10"); }

TEST(FileErrors, DepthEleven) { expect_format_error(raw_file(header(11), {0}), 7, "depth 11 is outside 1..10"); }

TEST(FileErrors, TruncatedSparseLevel) {
  // The root promises 3 level-1 blocks; the file holds 2. The level starts at byte 88.
  expect_format_error(raw_file(header(2), {0b111, 1, 1}), 88,
                      "level 1 needs 3 blocks (24 bytes) but the file ends at byte 104 (truncated file)");
  expect_format_error(raw_file(header(3), {0b11, 0b11}), 88, "level 1 needs 2 blocks");
  // Depth 3: level 2 starts after 1 + 2 words, at byte 104, and needs 2 + 1 blocks.
  expect_format_error(raw_file(header(3), {0b11, 0b11, 1, 1, 1}), 104, "level 2 needs 3 blocks");
  // A file cut inside a word.
  auto bytes = raw_file(header(2), kValidDepth2);
  bytes.resize(bytes.size() - 3);
  expect_format_error(bytes, 88, "level 1 needs 2 blocks (16 bytes) but the file ends at byte 101");
}

TEST(FileErrors, PayloadWordsMissing) {
  // nbits 1: each level is occupancy words then as many payload words.
  const std::vector<std::uint64_t> words = {0b11, 0xAA, 1, 2, 0xB1, 0xB2};
  EXPECT_NO_THROW(vola::parse(raw_file(header(2, 0, 1), words)));
  auto cut = words;
  cut.pop_back();
  expect_format_error(raw_file(header(2, 0, 1), cut), 96, "level 1 needs 2 blocks (32 bytes)");
  expect_format_error(raw_file(header(2, 0, 1), cut), 96, "payload word dropped by the reference writer");
  // Only the root occupancy word: its payload word is missing too.
  expect_format_error(raw_file(header(1, 0, 1), {1}), 80, "level 0 needs 1 blocks (16 bytes)");
}

TEST(FileErrors, ZeroOccupancyWordBelowTheRoot) {
  // Block 1 of level 1 (word 2, byte 96) is zero although root bit 63 is set.
  expect_format_error(raw_file(header(2), {1 | (1ull << 63), 1, 0}), 96,
                      "level 1 block 1 is empty although its parent bit is set");
  // With payload words the same block sits at word 3 (after the level-0 payload).
  expect_format_error(raw_file(header(2, 0, 1), {0b11, 7, 1, 0, 7, 7}), 104, "level 1 block 1 is empty");
}

TEST(FileErrors, TrailingGarbageAfterTheLevels) {
  auto bytes = raw_file(header(2), kValidDepth2);
  const std::string junk = "GARBAGE!GARBAGE!";
  bytes.insert(bytes.end(), junk.begin(), junk.end());
  expect_format_error(bytes, 104,
                      "16 bytes follow the last level and are not a vola extension (trailing garbage)");
  auto short_tail = raw_file(header(2), kValidDepth2);
  short_tail.push_back(0);
  expect_format_error(short_tail, 104, "1 bytes follow the last level");
}

TEST(FileErrors, ExtensionWithAnUnknownVersion) {
  std::uint64_t at = 0;
  auto bytes = file_with_extension(at);
  put_le<std::uint32_t>(bytes, at + 8, 7);
  expect_format_error(bytes, at + 8, "extension version 7 is not known");
  put_le<std::uint32_t>(bytes, at + 8, 0);
  expect_format_error(bytes, at + 8, "extension version 0 is not known");
}

TEST(FileErrors, ExtensionRecordLengthPastTheEnd) {
  std::uint64_t at = 0;
  auto bytes = file_with_extension(at);
  // Extension: magic (8), version (4), record count (4); the first record's header
  // is tag (4), flags (4), length (8); its body starts 32 bytes into the extension.
  ASSERT_EQ(get_le<std::uint64_t>(bytes, at + 24), 40u);  // the frame record
  // 40 bytes of frame, then the 16-byte trailer.
  put_le<std::uint64_t>(bytes, at + 24, 57);
  expect_format_error(bytes, at + 32, "record body needs 57 bytes but only 56 remain");
  put_le<std::uint64_t>(bytes, at + 24, ~std::uint64_t{0});
  expect_format_error(bytes, at + 32, "record body needs 18446744073709551615 bytes");
}

TEST(FileErrors, ExtensionWithMoreRecordsThanItHolds) {
  std::uint64_t at = 0;
  auto bytes = file_with_extension(at);
  put_le<std::uint32_t>(bytes, at + 12, 2);
  // The second record's head is the trailer; its "length" runs past the end.
  expect_format_error(bytes, bytes.size(), "record body needs");
}

TEST(FileErrors, ExtensionFollowedByBytes) {
  std::uint64_t at = 0;
  auto bytes = file_with_extension(at);
  const std::size_t end = bytes.size();
  bytes.resize(end + 8, 0);
  expect_format_error(bytes, end, "8 bytes follow the last extension record");
}

TEST(FileErrors, ExtensionFrameWithANonPositiveVoxelSize) {
  std::uint64_t at = 0;
  auto bytes = file_with_extension(at);
  // Frame body: quantization (1), padding (7), origin (24), voxel size (8).
  put_le<double>(bytes, at + 32 + 32, -1.0);
  expect_format_error(bytes, at + 16 + 48, "voxel size is not positive");
}

TEST(FileErrors, ExtensionFrameThatIsNotFinite) {
  // A grid the library cannot use (Quantizer::grid refuses it) is refused when read.
  std::uint64_t at = 0;
  const auto valid = file_with_extension(at);
  const double inf = std::numeric_limits<double>::infinity();
  auto bytes = valid;
  put_le<double>(bytes, at + 32 + 32, inf);  // voxel size
  expect_format_error(bytes, at + 16 + 48, "voxel size is not finite");
  for (std::size_t axis = 0; axis < 3; ++axis) {
    bytes = valid;
    put_le<double>(bytes, at + 32 + 8 + 8 * axis, axis == 1 ? -inf : std::numeric_limits<double>::quiet_NaN());
    expect_format_error(bytes, at + 16 + 24 + 8 * axis, "frame origin is not finite");  // record + 24
  }
}

TEST(FileErrors, ExtensionFrameWhoseFarCornerIsNotFinite) {
  // Finite origin and voxel size whose grid reaches past the doubles: every voxel centre
  // was infinite, and `vola export F.las` looked for a LAS scale without end.
  std::uint64_t at = 0;
  auto bytes = file_with_extension(at);
  for (std::size_t axis = 0; axis < 3; ++axis) put_le<double>(bytes, at + 32 + 8 + 8 * axis, 1e308);
  put_le<double>(bytes, at + 32 + 32, 1e307);
  expect_format_error(bytes, at + 16 + 24,
                      "the grid's far corner (origin + voxel size x 4^depth) is not a finite number");
}

// `bytes` (from file_with_extension) with `record` (tag, flags, length, body padded to 8)
// inserted after the frame record, and the record count raised: the record's offset.
std::uint64_t insert_record(std::vector<std::uint8_t>& bytes, std::uint64_t at, std::uint32_t tag,
                            const std::vector<std::uint8_t>& body) {
  std::vector<std::uint8_t> record(16);
  put_le<std::uint32_t>(record, 0, tag);
  put_le<std::uint64_t>(record, 8, body.size());
  record.insert(record.end(), body.begin(), body.end());
  record.resize((record.size() + 7) / 8 * 8, 0);
  const std::uint64_t where = at + 16 + 56;  // extension head (16) + the frame record (16 + 40)
  bytes.insert(bytes.begin() + static_cast<std::ptrdiff_t>(where), record.begin(), record.end());
  put_le<std::uint32_t>(bytes, at + 12, get_le<std::uint32_t>(bytes, at + 12) + 1);
  return where;
}

TEST(FileErrors, ASecondFrameOrCrsRecordAndANulInTheCrsAreRefused) {
  // The last of two records won silently, and PROJ read "EPSG:4326\0junk" as EPSG:4326.
  std::uint64_t at = 0;
  const auto valid = file_with_extension(at);
  auto bytes = valid;
  const std::vector<std::uint8_t> frame(valid.begin() + static_cast<std::ptrdiff_t>(at + 32),
                                        valid.begin() + static_cast<std::ptrdiff_t>(at + 72));
  std::uint64_t where = insert_record(bytes, at, 1, frame);
  expect_format_error(bytes, where, "a second frame record (a file holds one)");

  const std::string epsg = "EPSG:4326";
  bytes = valid;
  insert_record(bytes, at, 2, std::vector<std::uint8_t>(epsg.begin(), epsg.end()));
  where = insert_record(bytes, at, 2, std::vector<std::uint8_t>(epsg.begin(), epsg.end()));
  expect_format_error(bytes, where + 32, "a second CRS record (a file holds one)");  // after a 32-byte record

  bytes = valid;
  std::vector<std::uint8_t> with_nul(epsg.begin(), epsg.end());
  with_nul.push_back(0);
  with_nul.insert(with_nul.end(), {'j', 'u', 'n', 'k'});
  where = insert_record(bytes, at, 2, with_nul);
  expect_format_error(bytes, where + 16 + epsg.size(), "the CRS text holds a NUL byte");
}

TEST(FileErrors, AttributeValueCountDiffersFromTheVoxelCount) {
  // The extension of a 5-voxel tree with an attribute, after a 3-voxel tree's levels.
  vola::PointCloud five;
  five.xyz = {0, 0, 0, 1, 1, 1, 2, 2, 2, 3, 3, 3, 3, 0, 0};
  five.attributes.push_back({"intensity", vola::ValueType::u16, vola::Reduction::max, {1, 2, 3, 4, 5}});
  const vola::Tree donor = vola::build(five, {.depth = 1});
  ASSERT_EQ(donor.voxel_count(), 5u);
  const auto donor_bytes = vola::serialize(donor);
  const std::size_t donor_extension = 80 + 8 * donor.words().size();
  ASSERT_GT(donor_bytes.size(), donor_extension);

  auto bytes = raw_file(header(2), {0b11, 1, 0b11});  // 3 voxels
  const std::size_t at = bytes.size();
  bytes.insert(bytes.end(), donor_bytes.begin() + static_cast<std::ptrdiff_t>(donor_extension), donor_bytes.end());
  expect_format_error(bytes, at, "attribute 'intensity' has 5 values for 3 voxels");
}

TEST(FileErrors, AttributeTwiceUnderOneName) {
  vola::PointCloud cloud;
  cloud.xyz = {0, 0, 0, 3, 3, 3};
  cloud.attributes.push_back({"a", vola::ValueType::u8, vola::Reduction::last, {1, 2}});
  cloud.attributes.push_back({"b", vola::ValueType::u8, vola::Reduction::last, {3, 4}});
  const vola::Tree tree = vola::build(cloud, {.depth = 1});
  auto bytes = vola::serialize(tree);
  // Rename "b" to "a": the name is the last byte before the values of the last record.
  const std::size_t b_at = bytes.size() - 16 - 8;  // before the trailer: "b", 2 values, 5 zero bytes
  ASSERT_EQ(bytes[b_at], 'b');
  bytes[b_at] = 'a';
  reseal_extension(bytes, 80 + 8 * tree.words().size());
  const std::size_t record = b_at - 32;  // 16-byte record header + 16-byte attribute header
  expect_format_error(bytes, record, "attribute 'a' appears twice");
}

TEST(FileErrors, DenseFileShorterThanItsDepthImplies) {
  // Depth 2 dense: 1 + 64 words = 600 bytes.
  std::vector<std::uint64_t> body(65, 0);
  body[0] = 1;
  body[1] = 1;
  EXPECT_NO_THROW(vola::parse(raw_file(header(2, 1), body)));
  body.pop_back();
  expect_format_error(raw_file(header(2, 1), body), 592,
                      "a dense file of depth 2 needs 600 bytes, the file has 592 (truncated file)");
  // With payload words: 2 * 65 words.
  std::vector<std::uint64_t> with_payload(129, 0);
  expect_format_error(raw_file(header(2, 1, 1), with_payload), 1112,
                      "a dense file of depth 2 with payload needs 1120 bytes");
}

TEST(FileErrors, DenseUpperLevelDisagreesWithTheLeaf) {
  // Depth 2 dense: voxel (0,0,0) only. Level 0 = word 0, level 1 = words 1..64.
  std::vector<std::uint64_t> body(65, 0);
  body[0] = 1;
  body[1] = 1;
  body[0] |= 1ull << 63;  // a level-0 cell with nothing below it
  expect_format_error(raw_file(header(2, 1), body), 80,
                      "dense level 0 has 2 occupied cells that disagree with the 1 cells the leaf level implies");
  body[0] = 0;  // a leaf voxel without its level-0 cell
  expect_format_error(raw_file(header(2, 1), body), 80, "dense level 0 has 0 occupied cells");
  // Depth 3: the same count of level-1 cells, but in the wrong place. Level 1 starts
  // at word 1 (byte 88).
  std::vector<std::uint64_t> deep(1 + 64 + 4096, 0);
  deep[0] = 1;      // level 0: cell (0,0,0)
  deep[1] = 1u << 1;  // level 1: cell (1,0,0) instead of (0,0,0)
  deep[65] = 1;     // level 2: voxel (0,0,0)
  expect_format_error(raw_file(header(3, 1), deep), 88, "dense level 1 has 1 occupied cells that disagree");
}

TEST(FileErrors, CompressedFileWithoutLevels) {
  // Version 2 keeps the levels in the extension; an extension with only a frame is wrong.
  std::uint64_t at = 0;
  const auto grid = file_with_extension(at);
  RawHeader h = header(2);
  h.version = 2;
  auto bytes = raw_file(h, {});
  bytes.insert(bytes.end(), grid.begin() + static_cast<std::ptrdiff_t>(at), grid.end());
  expect_format_error(bytes, 80, "a version-2 file must hold its levels in the extension");
  // Nothing at all after the header.
  expect_format_error(raw_file(h, {}), 80, "extension magic needs 8 bytes but only 0 remain");
  // Version 2 is sparse only.
  h.mode = 1;
  expect_format_error(raw_file(h, {}), 6, "a compressed (version 2) file must be sparse");
}

TEST(FileErrors, CompressedLevelsInAVersionOneFile) {
  if (!vola::compression_available()) GTEST_SKIP() << "built without zstd";
  const std::vector<vola::Voxel> voxels = {{1, 2, 3}};
  const vola::Tree tree = vola::build_from_voxels(voxels, 2);
  auto bytes = vola::serialize(tree, {.compress = true});
  // Turn the version-2 file into a version-1 file with the levels in front.
  std::vector<std::uint8_t> v1(bytes.begin(), bytes.begin() + 80);
  put_le<std::uint16_t>(v1, 4, 1);
  for (std::uint64_t w : tree.words())
    for (int b = 0; b < 8; ++b) v1.push_back(static_cast<std::uint8_t>(w >> (8 * b)));
  const std::size_t at = v1.size();
  v1.insert(v1.end(), bytes.begin() + 80, bytes.end());
  expect_format_error(v1, at, "compressed levels in the extension of a version-1 file");
}

TEST(FileErrors, CorruptCompressedLevels) {
  if (!vola::compression_available()) GTEST_SKIP() << "built without zstd";
  const std::vector<vola::Voxel> voxels = {{1, 2, 3}, {9, 9, 9}};
  auto bytes = vola::serialize(vola::build_from_voxels(voxels, 2), {.compress = true});
  // The levels record is the last one; scramble the first byte of its first part (the
  // root level, coded occupancy: its first byte is always 0).
  vola::FileLayout layout;
  vola::parse(bytes, "ok", &layout);
  const std::size_t data = bytes.size() - 16 - ((layout.compressed_level_bytes + 7) / 8) * 8;
  bytes[data] ^= 0xFF;
  reseal_extension(bytes, 80);
  const auto error = format_error_of([&] { (void)vola::parse(bytes, "z"); });
  ASSERT_TRUE(error.has_value());
  EXPECT_THAT(error->cause(), HasSubstr("the coded occupancy level is corrupt"));
}

TEST(FileErrors, HugeDepthInATinyFileFailsFastWithoutAllocating) {
  // A header promising depth 10 (a dense body of 2^54 words; a sparse root with 64
  // children) in a few bytes: refused without allocating what the file does not hold.
  const auto start = std::chrono::steady_clock::now();
  LargestAllocation probe;
  expect_format_error(raw_file(header(10), {~std::uint64_t{0}}), 88, "level 1 needs 64 blocks");
  expect_format_error(raw_file(header(10, 1), {~std::uint64_t{0}}), 88, "a dense file of depth 10 needs");
  expect_format_error(raw_file(header(10, 1, 1), {}), 80, "a dense file of depth 10 with payload needs");
  const auto elapsed = std::chrono::steady_clock::now() - start;
  EXPECT_LT(probe.bytes(), std::size_t{1} << 20) << "largest allocation";
  EXPECT_LT(elapsed, std::chrono::seconds(2));
}

TEST(FileErrors, CompressedRecordClaimingAHugeSizeIsRefusedBeforeAllocating) {
  if (!vola::compression_available()) GTEST_SKIP() << "built without zstd";
  const std::vector<vola::Voxel> voxels = {{1, 2, 3}};
  auto bytes = vola::serialize(vola::build_from_voxels(voxels, 2), {.compress = true});
  // Walk the extension's records (from byte 80 + magic, version, count) to the levels
  // record (tag 4): u32 parts, u32 reserved, then per part u64 raw size, u64 packed size.
  std::size_t record = 96;
  while (get_le<std::uint32_t>(bytes, record) != 4) record += 16 + ((get_le<std::uint64_t>(bytes, record + 8) + 7) / 8) * 8;
  const std::size_t raw_size_at = record + 16 + 8;  // the first part (level 0)
  ASSERT_EQ(get_le<std::uint64_t>(bytes, raw_size_at), 8u);  // one root word
  put_le<std::uint64_t>(bytes, raw_size_at, std::uint64_t{1} << 40);
  LargestAllocation probe;
  const auto error = format_error_of([&] { (void)vola::parse(bytes, "huge"); });
  ASSERT_TRUE(error.has_value());
  EXPECT_THAT(error->cause(), HasSubstr("more than any real data compresses"));
  EXPECT_LT(probe.bytes(), std::size_t{1} << 20);
}

}  // namespace
}  // namespace vola_test

// A hostile file's bytes quoted in an error (a PLY header keyword, a text value) put an
// escape sequence on the user's terminal: control characters are written as \xNN.
TEST(FileErrors, ControlCharactersInCausesAreEscaped) {
  const vola::FormatError e("bad.ply", 12, "unknown header keyword '\x1b[31mevil\x1b[0m\r\x7f\x01'");
  EXPECT_EQ(e.cause(), "unknown header keyword '\\x1b[31mevil\\x1b[0m\\x0d\\x7f\\x01'");
  EXPECT_STREQ(e.what(), "bad.ply: byte 12: unknown header keyword '\\x1b[31mevil\\x1b[0m\\x0d\\x7f\\x01'");
  // Tabs, newlines and UTF-8 stay as they are.
  EXPECT_EQ(vola::FormatError("f", std::nullopt, "H\xc3\xb6he\tline\n").cause(), "H\xc3\xb6he\tline\n");
}
