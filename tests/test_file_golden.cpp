// The reference implementation's golden files (shared/golden): every case of
// MANIFEST.tsv is read and checked against expected_voxels.txt / spec_voxels.txt, and
// rebuilt from input.txt and compared byte for byte (lat/lon within 1e-9 degree).
// The two documented differences are asserted, not skipped:
//   zero_payload_sparse - the reference file is corrupt (a zero payload word dropped);
//   single_point_dense  - the reference crashed and wrote nothing.
#include <bit>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <sstream>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "test_support.hpp"
#include "vola/builder.hpp"
#include "vola/file.hpp"
#include "vola/geo/crs.hpp"
#include "vola/io/text_points.hpp"

namespace vola_test {
namespace {

constexpr double kLatLonTolerance = 1e-9;  // degrees; PROJ versions may differ in the last bits
const std::string kCorruptReferenceCase = "zero_payload_sparse";
const std::string kNoReferenceFileCase = "single_point_dense";

// The input points of a case, with payload columns 3.. when the case has nbits.
vola::PointCloud read_case_points(const fs::path& case_dir, const GoldenParams& params) {
  vola::io::TextColumns columns;
  if (params.nbits > 0) {
    const int n = count_columns(case_dir / "input.txt");
    for (int c = 3; c < n; ++c) columns.payload.push_back(c);
  }
  return vola::io::read_text_points((case_dir / "input.txt").string(), columns);
}

// What vola writes for the case: toolkit quantization with the case's bbox and depth.
std::vector<std::uint8_t> rebuild(const fs::path& case_dir) {
  const GoldenParams params = read_params(case_dir);
  const vola::PointCloud cloud = read_case_points(case_dir, params);
  vola::BuildOptions options;
  options.quantization = vola::Quantization::toolkit;
  options.depth = params.depth;
  options.bbox = params.bbox;
  options.payload = params.nbits > 0;
  options.epsg = params.crs;
  vola::Tree tree = vola::build(cloud, options);
  const auto [lat, lon] = vola::geo::centre_lat_lon(params.crs, params.bbox);
  tree.georef().lat = lat;
  tree.georef().lon = lon;
  return vola::serialize(tree, {.layout = params.dense ? vola::Layout::dense : vola::Layout::sparse});
}

// Equal bytes, except lat/lon (bytes 16..31) which must agree within the tolerance.
::testing::AssertionResult same_file(const std::vector<std::uint8_t>& reference,
                                     const std::vector<std::uint8_t>& ours) {
  if (reference.size() != ours.size())
    return ::testing::AssertionFailure() << "sizes differ: reference " << reference.size() << ", ours " << ours.size();
  if (reference.size() < 80) return ::testing::AssertionFailure() << "shorter than a header";
  for (std::size_t i = 0; i < reference.size(); ++i) {
    if (i >= 16 && i < 32) continue;
    if (reference[i] != ours[i])
      return ::testing::AssertionFailure() << "first difference at byte " << i << ": reference "
                                           << int(reference[i]) << ", ours " << int(ours[i]);
  }
  for (std::size_t at : {16u, 24u}) {
    const double a = get_le<double>(reference, at), b = get_le<double>(ours, at);
    if (!(std::abs(a - b) <= kLatLonTolerance))
      return ::testing::AssertionFailure() << (at == 16 ? "lat" : "lon") << " differs: reference "
                                           << std::setprecision(17) << a << ", ours " << b;
  }
  return ::testing::AssertionSuccess();
}

std::vector<std::uint8_t> rebuild_case(const fs::path& golden, const std::string& name) {
  return rebuild(golden / name);
}

// ---- the documented differences ----

// The reference dropped the zero payload word of the block holding the voxel whose
// payload is all zeros; we write it.
void check_zero_payload_sparse(const fs::path& golden) {
  const fs::path dir = golden / kCorruptReferenceCase;
  const auto reference = read_bytes(dir / (kCorruptReferenceCase + ".vol"));

  // 1. The reference file is refused: level 1 (6 words: 3 occupancy + 3 payload)
  //    starts at byte 96 and the file ends at 136.
  const auto error = format_error_of([&] { (void)vola::parse(reference, "ref"); });
  ASSERT_TRUE(error.has_value()) << "the corrupt reference file must not parse";
  EXPECT_EQ(error->offset(), std::optional<std::uint64_t>(96));
  EXPECT_THAT(error->cause(), ::testing::HasSubstr("zero-payload bug"));

  // 2. Ours is the reference plus the missing word, in the payload slot of the
  //    level-1 block that holds the all-zero-payload voxel.
  const GoldenParams params = read_params(dir);
  const vola::PointCloud cloud = read_case_points(dir, params);
  std::optional<Xyz> zero_voxel;
  const vola::Quantizer q = vola::Quantizer::toolkit(params.bbox, params.depth);
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    if (cloud.payload[i] != 0) continue;
    vola::Voxel v;
    ASSERT_TRUE(q.to_voxel({cloud.xyz[3 * i], cloud.xyz[3 * i + 1], cloud.xyz[3 * i + 2]}, v));
    zero_voxel = to_xyz(v);
  }
  ASSERT_TRUE(zero_voxel.has_value()) << "input.txt has no all-zero payload row";
  const std::uint64_t root = get_le<std::uint64_t>(reference, 80);
  const unsigned bit = slow_local_index(*zero_voxel, 0, params.depth);
  ASSERT_TRUE((root >> bit) & 1u);
  const std::size_t blocks = static_cast<std::size_t>(std::popcount(root));
  const std::size_t index = static_cast<std::size_t>(std::popcount(root & ((std::uint64_t{1} << bit) - 1)));
  // Header, level 0 (occupancy + payload), level-1 occupancy, then the payload slots.
  const std::size_t slot = 80 + 16 + 8 * blocks + 8 * index;

  const auto ours = rebuild(dir);
  EXPECT_EQ(ours.size(), 80 + 16 + 16 * blocks);
  EXPECT_EQ(ours.size(), reference.size() + 8);
  ASSERT_LE(slot + 8, ours.size());
  EXPECT_EQ(get_le<std::uint64_t>(ours, slot), 0u);
  std::vector<std::uint8_t> without_slot(ours.begin(), ours.begin() + static_cast<std::ptrdiff_t>(slot));
  without_slot.insert(without_slot.end(), ours.begin() + static_cast<std::ptrdiff_t>(slot + 8), ours.end());
  EXPECT_TRUE(same_file(reference, without_slot));

  // 3. Ours reads back to the expected voxels, with the payloads the dense reference
  //    file (same input, valid) gives them: here every voxel has a block of its own.
  const vola::Tree tree = vola::parse(ours, "ours");
  EXPECT_EQ(voxel_set(tree), read_voxel_list(dir / "expected_voxels.txt"));
  const auto payloads = read_spec_payloads(golden / "zero_payload_dense" / "spec_voxels.txt");
  EXPECT_EQ(payloads.size(), tree.voxel_count());
  for (const auto& [v, payload] : payloads) EXPECT_EQ(tree.voxel_payload(to_voxel(v)), payload);
  EXPECT_EQ(tree.voxel_payload(to_voxel(*zero_voxel)), std::optional<std::uint64_t>(0));
}

// The reference crashed; we write a valid dense file whose only voxel is (0,0,0).
void check_single_point_dense(const fs::path& golden) {
  const fs::path dir = golden / kNoReferenceFileCase;
  EXPECT_FALSE(fs::exists(dir / (kNoReferenceFileCase + ".dvol")));
  const auto ours = rebuild(dir);
  const GoldenParams params = read_params(dir);
  ASSERT_TRUE(params.dense);
  std::size_t words = 0;
  for (int level = 0; level < params.depth; ++level) words += std::size_t{1} << (6 * level);
  EXPECT_EQ(ours.size(), 80 + 8 * words);  // FORMAT.md 5
  const vola::Tree tree = vola::parse(ours, "ours");
  EXPECT_EQ(voxel_set(tree), (XyzSet{{0, 0, 0}}));
  EXPECT_EQ(voxel_set(tree), read_voxel_list(dir / "expected_voxels.txt"));
  // Its header is the sparse reference's (same input), but for the mode byte.
  auto sparse_reference = read_bytes(golden / "single_point_sparse" / "single_point_sparse.vol");
  sparse_reference.resize(80);
  std::vector<std::uint8_t> header(ours.begin(), ours.begin() + 80);
  EXPECT_EQ(header[6], 1u);
  header[6] = 0;
  EXPECT_TRUE(same_file(sparse_reference, header));
}

// ---- every case ----

TEST(Golden, ManifestAndCaseFoldersAgree) {
  VOLA_REQUIRE_GOLDEN(golden);
  const auto cases = read_manifest(golden);
  ASSERT_FALSE(cases.empty());
  std::set<std::string> listed, folders;
  for (const auto& c : cases) listed.insert(c.name);
  EXPECT_EQ(listed.size(), cases.size()) << "a case is listed twice";
  for (const auto& entry : fs::directory_iterator(golden))
    if (entry.is_directory()) folders.insert(entry.path().filename().string());
  EXPECT_EQ(listed, folders);
  // Exactly one case has no reference file, and it is the documented one.
  for (const auto& c : cases) EXPECT_EQ(c.has_file(), c.name != kNoReferenceFileCase) << c.name;
}

TEST(Golden, EveryReferenceFileReadsToTheExpectedVoxels) {
  VOLA_REQUIRE_GOLDEN(golden);
  std::size_t checked = 0;
  const auto cases = read_manifest(golden);
  for (const auto& c : cases) {
    SCOPED_TRACE("case " + c.name);
    const fs::path dir = golden / c.name;
    const XyzSet expected = read_voxel_list(dir / "expected_voxels.txt");
    EXPECT_EQ(expected.size(), c.nvoxels);
    if (!c.has_file()) {
      ASSERT_EQ(c.name, kNoReferenceFileCase);  // checked by SinglePointDense below
      ++checked;
      continue;
    }
    const auto bytes = golden_file_bytes(golden, c);
    ASSERT_TRUE(c.vol_size.has_value());
    EXPECT_EQ(bytes.size(), *c.vol_size);
    if (c.name == kCorruptReferenceCase) {
      EXPECT_THROW((void)vola::parse(bytes, c.name), vola::FormatError);  // details: ZeroPayloadSparse
      ++checked;
      continue;
    }
    vola::FileLayout layout;
    const vola::Tree tree = vola::parse(bytes, c.name, &layout);
    EXPECT_EQ(tree.depth(), c.depth);
    EXPECT_EQ(static_cast<int>(layout.header.layout), c.mode);
    EXPECT_EQ(static_cast<int>(layout.header.nbits), c.nbits);
    EXPECT_EQ(layout.header.epsg, c.crs);
    EXPECT_EQ(layout.extension_offset, 0u) << "reference files have no extension";
    EXPECT_EQ(tree.voxel_count(), c.nvoxels);
    EXPECT_EQ(voxel_set(tree), expected);
    if (c.nbits > 0) {
      const auto payloads = read_spec_payloads(dir / "spec_voxels.txt");
      EXPECT_EQ(payloads.size(), expected.size());
      for (const auto& [v, payload] : payloads)
        EXPECT_EQ(tree.voxel_payload(to_voxel(v)), payload) << v[0] << " " << v[1] << " " << v[2];
    } else {
      EXPECT_EQ(read_voxel_list(dir / "spec_voxels.txt"), expected);
      EXPECT_FALSE(tree.voxel_payload(to_voxel(*expected.begin())).has_value());
    }
    // The mapped reader agrees (gzipped files are read from memory only).
    if (fs::path(c.vol_file).extension() != ".gz") {
      const vola::Tree mapped = vola::open_mapped((dir / c.vol_file).string());
      EXPECT_EQ(mapped.is_mapped(), c.mode == 0);
      EXPECT_EQ(voxel_set(mapped), expected);
    }
    ++checked;
  }
  EXPECT_EQ(checked, cases.size());
}

TEST(Golden, EveryCaseRebuildsByteForByteFromItsInput) {
  VOLA_REQUIRE_GOLDEN(golden);
  std::size_t checked = 0;
  const auto cases = read_manifest(golden);
  for (const auto& c : cases) {
    SCOPED_TRACE("case " + c.name);
    if (c.name == kNoReferenceFileCase) {
      check_single_point_dense(golden);
    } else if (c.name == kCorruptReferenceCase) {
      check_zero_payload_sparse(golden);
    } else {
      const GoldenParams params = read_params(golden / c.name);
      EXPECT_EQ(params.depth, c.depth);
      EXPECT_EQ(params.dense ? 1 : 0, c.mode);
      EXPECT_TRUE(same_file(golden_file_bytes(golden, c), rebuild(golden / c.name)));
    }
    ++checked;
  }
  EXPECT_EQ(checked, cases.size());
}

// ---- the special cases on their own ----

TEST(Golden, ZeroPayloadSparseReferenceIsCorruptAndOursHasTheMissingWord) {
  VOLA_REQUIRE_GOLDEN(golden);
  check_zero_payload_sparse(golden);
}

TEST(Golden, SinglePointDenseReferenceCrashedAndOursIsValid) {
  VOLA_REQUIRE_GOLDEN(golden);
  check_single_point_dense(golden);
}

TEST(Golden, SinglePointSparseMatchesByteForByte) {
  VOLA_REQUIRE_GOLDEN(golden);
  const auto reference = read_bytes(golden / "single_point_sparse" / "single_point_sparse.vol");
  EXPECT_TRUE(same_file(reference, rebuild_case(golden, "single_point_sparse")));
  EXPECT_EQ(voxel_set(vola::parse(reference)), (XyzSet{{0, 0, 0}}));
}

TEST(Golden, Crs29902HeaderCarriesDublinsLatLon) {
  // README: header lat 53.3457, lon -6.2673 for the Irish Grid case.
  VOLA_REQUIRE_GOLDEN(golden);
  const auto ours = rebuild_case(golden, "crs29902_sparse");
  EXPECT_NEAR(get_le<double>(ours, 16), 53.3457, 5e-5);
  EXPECT_NEAR(get_le<double>(ours, 24), -6.2673, 5e-5);
  EXPECT_EQ(get_le<std::uint32_t>(ours, 12), 29902u);
}

TEST(Golden, D1SparseIsOneWord) {
  // README: 8 voxels, one word 0x9004040800000301, 88 bytes; dense differs in byte 6 only.
  VOLA_REQUIRE_GOLDEN(golden);
  const auto sparse = read_bytes(golden / "d1_sparse" / "d1_sparse.vol");
  auto dense = read_bytes(golden / "d1_dense" / "d1_dense.dvol");
  ASSERT_EQ(sparse.size(), 88u);
  EXPECT_EQ(get_le<std::uint64_t>(sparse, 80), 0x9004040800000301ull);
  EXPECT_EQ(vola::parse(sparse).words()[0], 0x9004040800000301ull);
  ASSERT_EQ(dense.size(), 88u);
  EXPECT_EQ(dense[6], 1u);
  dense[6] = 0;
  EXPECT_EQ(dense, sparse);
}

}  // namespace
}  // namespace vola_test
