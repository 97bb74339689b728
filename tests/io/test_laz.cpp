// The LAZ codec against files written by LASzip, laz-perf, PDAL, laspy and Entwine: the
// decoded records must hash to what laz-perf 0.0.7 decoded (EXPECTED.txt, read at run
// time so that new files are covered), equal the uncompressed twins, and survive an
// encode -> decode round trip; malformed input must be refused with FormatError.
#include <gtest/gtest.h>

#include <sstream>

#include "io_test_data.hpp"
#include "laz_test_support.hpp"
#include "sha256.hpp"
#include "vola/error.hpp"

namespace {

namespace fs = vola_io_test::fs;
using vola_laz_test::Bytes;
using vola_laz_test::LasFile;

// The word after `key` on an EXPECTED.txt line.
std::string expected_word(const std::string& line, const std::string& key) {
  const auto at = line.find(key);
  if (at == std::string::npos) return {};
  std::istringstream in(line.substr(at + key.size()));
  std::string word;
  in >> word;
  return word;
}

TEST(LazDecode, EveryFileHashesAsLazPerfDecodedIt) {
  VOLA_REQUIRE_DATA(data);
  const auto files = vola_io_test::files_ending(data / "laz", ".laz");
  ASSERT_FALSE(files.empty());
  for (const fs::path& path : files) {
    SCOPED_TRACE(path.filename().string());
    const std::string line = vola_io_test::expected_line(data, path.filename().string());
    const std::string sha = expected_word(line, "points_sha256=");
    ASSERT_EQ(sha.size(), 64u) << "EXPECTED.txt has no points_sha256 for this file";
    const LasFile file = vola_laz_test::read_las_file(path);
    ASSERT_FALSE(file.laszip.empty());
    EXPECT_EQ(vola_io_test::expected_integer(line, "decoded n="), file.point_count);
    Bytes records;
    try {
      records = vola_laz_test::decode_all(file);
    } catch (const vola::Error& e) {
      ADD_FAILURE() << e.what();
      continue;
    }
    EXPECT_EQ(vola_test::sha256_hex(records), sha);
  }
}

TEST(LazDecode, LasTwinsGiveTheSameRecords) {
  VOLA_REQUIRE_DATA(data);
  const std::pair<const char*, const char*> twins[] = {
      {"laz/laspy_simple.laz", "las/pdal_1.2-with-color.las"},
      {"laz/laspy_extra.laz", "las/pdal_extrabytes.las"},
      {"laz/pdal_autzen_trim.laz", "las/pdal_autzen_trim.las"}};
  for (const auto& [laz, las] : twins) {
    SCOPED_TRACE(laz);
    const LasFile compressed = vola_laz_test::read_las_file(data / laz);
    const LasFile plain = vola_laz_test::read_las_file(data / las);
    ASSERT_EQ(compressed.record_length, plain.record_length);
    ASSERT_EQ(compressed.point_count, plain.point_count);
    EXPECT_TRUE(vola_laz_test::decode_all(compressed) == vola_laz_test::las_records(plain));
  }
}

}  // namespace
