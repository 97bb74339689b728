// The LAZ codec against files written by LASzip, laz-perf, PDAL, laspy and Entwine: the
// decoded records must hash to what laz-perf 0.0.7 decoded (EXPECTED.txt, read at run
// time so that new files are covered), equal the uncompressed twins, and survive an
// encode -> decode round trip; malformed input must be refused with FormatError.
#include <gtest/gtest.h>

#include <cstdlib>
#include <cstring>
#include <sstream>
#include <string>

#include "io_test_data.hpp"
#include "laz_test_support.hpp"
#include "sha256.hpp"
#include "vola/error.hpp"
#include "vola/io/las.hpp"

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

// Coordinates alone (the occupancy conversion's decode): X, Y and Z exactly as decoded
// whole (layered chunks skip their other layers); point-wise chunks decode everything.
TEST(LazDecode, CoordinatesAloneAreTheWholeDecodesCoordinates) {
  VOLA_REQUIRE_DATA(data);
  std::size_t layered = 0;
  for (const fs::path& path : vola_io_test::files_ending(data / "laz", ".laz")) {
    SCOPED_TRACE(path.filename().string());
    const LasFile file = vola_laz_test::read_las_file(path);
    const Bytes whole = vola_laz_test::decode_all(file);
    const Bytes coordinates = vola_laz_test::decode_all(file, true);
    ASSERT_EQ(coordinates.size(), whole.size());
    if (file.point_format < 6) {
      EXPECT_TRUE(coordinates == whole);
      continue;
    }
    ++layered;
    const std::size_t n = file.record_length;
    bool others_differ = false;
    for (std::uint64_t i = 0; i < file.point_count; ++i) {
      ASSERT_EQ(std::memcmp(coordinates.data() + i * n, whole.data() + i * n, 12), 0) << "record " << i;
      others_differ = others_differ || std::memcmp(coordinates.data() + i * n, whole.data() + i * n, n) != 0;
    }
    // The layers were skipped (a file whose other fields never change would not show it).
    if (file.point_count > 100) {
      EXPECT_TRUE(others_differ);
    }
  }
  EXPECT_GE(layered, 3u);  // formats 6, 7 and 8 among the shared files
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

namespace {

// Every record of `reader` from its start, by read_records().
Bytes read_every_record(vola::io::LasReader& reader) {
  reader.rewind();
  Bytes out;
  for (;;) {
    const auto records = reader.read_records(997);  // batches that end inside chunks
    if (records.empty()) return out;
    out.insert(out.end(), records.begin(), records.end());
  }
}

}  // namespace

// A conversion with attributes reads a LAZ file two or three times; its records are
// decoded once and kept in a temporary file. The kept records read back are the decoded
// ones, a pass with coordinates alone keeps whole records, a new COPC selection starts
// over, and a folder where no file can be made leaves the reader decoding as before.
TEST(LazDecode, KeptRecordsReadBackAsDecoded) {
  VOLA_REQUIRE_DATA(data);
  for (const fs::path& path : vola_io_test::files_ending(data / "laz", ".laz")) {
    SCOPED_TRACE(path.filename().string());
    const Bytes decoded = vola_laz_test::decode_all(vola_laz_test::read_las_file(path));
    vola::io::LasReader reader(path.string());
    ASSERT_TRUE(reader.keep_decoded_records());
    reader.set_coordinates_only(true);  // ignored while records are being kept
    EXPECT_FALSE(reader.reads_kept_records());
    EXPECT_TRUE(read_every_record(reader) == decoded);
    EXPECT_TRUE(reader.reads_kept_records());
    EXPECT_TRUE(read_every_record(reader) == decoded);
    if (reader.header().copc) {
      reader.select_copc_nodes(std::nullopt, 0);  // the root node alone
      EXPECT_FALSE(reader.reads_kept_records());
      const Bytes root = read_every_record(reader);
      EXPECT_EQ(root.size(), reader.points_total() * reader.header().record_length);
      EXPECT_TRUE(reader.reads_kept_records());
      EXPECT_TRUE(read_every_record(reader) == root);
    }
  }
  const char* before = std::getenv("TMPDIR");
  const std::string saved = before ? before : "";
  ::setenv("TMPDIR", "/nonexistent/folder", 1);
  vola::io::LasReader reader((data / "laz" / "pdal_autzen_trim.laz").string());
  EXPECT_FALSE(reader.keep_decoded_records());
  const Bytes twice[2] = {read_every_record(reader), read_every_record(reader)};
  EXPECT_FALSE(reader.reads_kept_records());
  EXPECT_TRUE(twice[0] == twice[1]);
  if (before)
    ::setenv("TMPDIR", saved.c_str(), 1);
  else
    ::unsetenv("TMPDIR");
}
