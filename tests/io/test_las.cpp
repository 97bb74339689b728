// The LAS reader against every LAS file in the shared data: counts, formats, record
// lengths, classes and CRS as EXPECTED.txt (an independent reader) records them; LAZ
// files read as the same records; broken files refused with a clear error.
#include <gtest/gtest.h>

#include <fstream>
#include <limits>
#include <map>
#include <regex>

#include "io_test_data.hpp"
#include "vola/geo/crs.hpp"
#include "vola/io/las.hpp"

namespace {

using vola_io_test::data_dir;
using vola_io_test::expected_line;
namespace fs = vola_io_test::fs;

std::vector<fs::path> las_files(const fs::path& data) {
  auto files = vola_io_test::files_ending(data / "las", ".las");
  return files;
}

// "classes={1: 789, 2: 276}" -> {1: 789, 2: 276}
std::map<int, std::uint64_t> expected_classes(const std::string& line) {
  std::map<int, std::uint64_t> out;
  const auto at = line.find("classes={");
  if (at == std::string::npos) return out;
  const std::string body = line.substr(at + 9, line.find('}', at) - at - 9);
  const std::regex pair(R"((\d+):\s*(\d+))");
  for (auto it = std::sregex_iterator(body.begin(), body.end(), pair); it != std::sregex_iterator(); ++it)
    out[std::stoi((*it)[1])] = std::stoull((*it)[2]);
  return out;
}

std::optional<std::uint32_t> expected_epsg(const std::string& line) {
  std::smatch m;
  if (std::regex_search(line, m, std::regex(R"(ProjCS=(\d+))")) && m[1] != "32767") return std::stoul(m[1]);
  if (std::regex_search(line, m, std::regex(R"(GeogCS=(\d+))")) && !std::regex_search(line, std::regex("ProjCS=")) &&
      m[1] != "32767")
    return std::stoul(m[1]);
  return std::nullopt;
}

TEST(Las, EveryFileReadsAsTheIndependentReaderFound) {
  VOLA_REQUIRE_DATA(data);
  const auto files = las_files(data);
  ASSERT_GE(files.size(), 20u) << "expected the shared LAS files under " << data / "las";
  for (const auto& file : files) {
    SCOPED_TRACE(file.string());
    const std::string line = expected_line(data, file.filename().string());
    vola::io::LasReader reader(file.string());
    const auto& h = reader.header();
    EXPECT_EQ(h.point_count, vola_io_test::expected_integer(line, " n=").value());
    EXPECT_EQ(h.point_format, vola_io_test::expected_integer(line, " pf=").value());
    EXPECT_EQ(h.record_length, vola_io_test::expected_integer(line, "reclen=").value());
    std::smatch version;
    ASSERT_TRUE(std::regex_search(line, version, std::regex(R"(LAS (\d)\.(\d))")));
    EXPECT_EQ(h.version_minor, std::stoi(version[2]));
    const auto code = expected_epsg(line);
    if (code && !h.epsg && !h.wkt.empty()) {
      // The keys' linear unit overrides the code's own (pdal_mvk-thin.las: EPSG:26995, a
      // metre CRS, in US survey feet), as GDAL reads them: the code's CRS in another unit.
      const auto crs = vola::geo::describe_crs(h.wkt), own = vola::geo::describe_crs("EPSG:" + std::to_string(*code));
      EXPECT_EQ(crs.name, own.name);
      EXPECT_NE(crs.horizontal_unit, own.horizontal_unit);
    } else {
      EXPECT_EQ(h.epsg, code);
    }

    std::map<int, std::uint64_t> classes;
    vola::Box box{{1e300, 1e300, 1e300}, {-1e300, -1e300, -1e300}};
    vola::io::LasChunk chunk;
    std::uint64_t total = 0, rgb_max = 0;
    while (const std::size_t n = reader.read(chunk, 777)) {  // an odd chunk size crosses boundaries
      total += n;
      for (std::size_t i = 0; i < n; ++i) {
        ++classes[chunk.classification[i]];
        for (int a = 0; a < 3; ++a) {
          box.min[a] = std::min(box.min[a], chunk.xyz[3 * i + a]);
          box.max[a] = std::max(box.max[a], chunk.xyz[3 * i + a]);
        }
        if (!chunk.red.empty()) rgb_max = std::max<std::uint64_t>({rgb_max, chunk.red[i], chunk.green[i], chunk.blue[i]});
      }
    }
    EXPECT_EQ(total, h.point_count);
    EXPECT_EQ(classes, expected_classes(line));
    if (const auto expected_rgb = vola_io_test::expected_integer(line, "rgb_max=")) {
      EXPECT_EQ(rgb_max, *expected_rgb);
    }
    // Where the independent reader found the points inside the header bounds, so do we.
    if (line.find("decoded_bounds_ok=True") != std::string::npos) {
      for (int a = 0; a < 3; ++a) {
        EXPECT_GE(box.min[a], h.min[a] - h.scale[a]);
        EXPECT_LE(box.max[a], h.max[a] + h.scale[a]);
      }
    }
  }
}

TEST(Las, WktRecordIsExposed) {
  VOLA_REQUIRE_DATA(data);
  vola::io::LasReader reader((data / "las" / "pdal_wontcompress3.las").string());
  EXPECT_NE(reader.header().wkt.find("AUTHORITY[\"EPSG\",\"26919\"]"), std::string::npos);
  EXPECT_FALSE(reader.header().epsg.has_value());  // no GeoKeyDirectory in this file
}

TEST(Las, ExtraBytesBecomeFields) {
  VOLA_REQUIRE_DATA(data);
  vola::io::LasReader reader((data / "las" / "pdal_extrabytes.las").string());
  const auto& fields = reader.header().extra_fields;
  ASSERT_FALSE(fields.empty());
  std::uint32_t end = 0;
  for (const auto& f : fields) end = std::max(end, f.offset + f.size);
  EXPECT_LE(end, reader.header().record_length);
  EXPECT_EQ(end, reader.header().record_length);  // this file's extra bytes fill the record
}

// LAZ through LasReader: the point count and bounds EXPECTED.txt records (laz-perf's
// decode) and every record read back, in batches that cross chunk boundaries, twice.
TEST(Las, LazReadsLikeLas) {
  VOLA_REQUIRE_DATA(data);
  const auto files = vola_io_test::files_ending(data / "laz", ".laz");
  ASSERT_FALSE(files.empty());
  for (const auto& file : files) {
    SCOPED_TRACE(file.string());
    vola::io::LasReader reader(file.string());
    const auto& hd = reader.header();
    ASSERT_TRUE(hd.compressed());
    const std::string line = vola_io_test::expected_line(data, file.filename().string());
    EXPECT_EQ(vola_io_test::expected_integer(line, "decoded n="), hd.point_count);
    for (int pass = 0; pass < 2; ++pass) {
      std::uint64_t points = 0;
      vola::io::LasChunk chunk;
      while (const std::size_t n = reader.read(chunk, 7919)) {  // a prime: batches straddle chunks
        for (std::size_t i = 0; i < n; ++i)
          for (int a = 0; a < 3; ++a) {
            EXPECT_GE(chunk.xyz[3 * i + a], hd.min[a] - 1e-6 - hd.scale[a]);
            EXPECT_LE(chunk.xyz[3 * i + a], hd.max[a] + 1e-6 + hd.scale[a]);
          }
        points += n;
      }
      EXPECT_EQ(points, hd.point_count);
      reader.rewind();
    }
  }
}

TEST(Las, TruncatedAndCorruptFilesAreRefused) {
  VOLA_REQUIRE_DATA(data);
  const auto bytes = vola_test::read_bytes(data / "las" / "pdal_autzen_pf1.las");
  const vola_test::TempDir dir;
  const auto write = [&](const std::vector<std::uint8_t>& b) {
    const auto path = dir.path() / "broken.las";
    vola_test::write_bytes(path, b);
    return path.string();
  };
  auto expect_error = [&](const std::vector<std::uint8_t>& b, const char* why) {
    SCOPED_TRACE(why);
    EXPECT_THROW(vola::io::LasReader reader(write(b)), vola::FormatError);
  };
  expect_error({bytes.begin(), bytes.begin() + 100}, "cut inside the header");
  expect_error({bytes.begin(), bytes.end() - 5}, "cut inside the points");
  auto bad = bytes;
  bad[0] = 'X';
  expect_error(bad, "no signature");
  bad = bytes;
  bad[104] = 11;
  expect_error(bad, "unknown point format");
  bad = bytes;
  bad[105] = 10;
  bad[106] = 0;
  expect_error(bad, "record shorter than the format");
  bad = bytes;
  bad[100] = 200;  // 200 VLRs that are not there
  expect_error(bad, "VLR count past the end");
}

// A NaN, infinite or zero scale made every point NaN (or one point), and the builders
// dropped them all with exit status 0; a NaN offset likewise.
TEST(Las, ScalesAndOffsetsThatMakeNoCoordinateAreRefusedWithTheirOffset) {
  VOLA_REQUIRE_DATA(data);
  const auto bytes = vola_test::read_bytes(data / "las" / "pdal_autzen_pf1.las");
  const vola_test::TempDir dir;
  const auto path = (dir.path() / "scaled.las").string();
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  struct Case {
    std::size_t at;
    double value;
    const char* cause;
  };
  for (const Case& c : {Case{131, nan, "x scale is NaN"}, Case{139, 0.0, "y scale is 0"},
                        Case{147, -inf, "z scale is infinite"}, Case{155, nan, "x offset is NaN"},
                        Case{171, inf, "z offset is infinite"}}) {
    SCOPED_TRACE(c.cause);
    auto bad = bytes;
    vola_test::put_le(bad, c.at, c.value);
    vola_test::write_bytes(path, bad);
    const auto error = vola_test::format_error_of([&] { vola::io::LasReader reader(path); });
    ASSERT_TRUE(error.has_value());
    EXPECT_EQ(error->file(), path);
    EXPECT_EQ(error->offset(), c.at);
    EXPECT_EQ(error->cause(), c.cause);
  }
}

}  // namespace

// GeoTIFF keys name a projected CRS and units: a linear unit other than the code's own
// makes the code's CRS in that unit, and a vertical unit other than the horizontal one a
// compound CRS with heights in it, as GDAL reads them (tests/io/geokeys_vs_gdal.py
// compares with GDAL on every shared file and on made-up keys).
TEST(Las, UnitKeysOtherThanTheCodesQualifyTheCrs) {
  using vola::geo::keyed_projected_crs;
  const std::string feet = keyed_projected_crs(26995, 9003);  // NAD83 / Mississippi West in US survey feet
  ASSERT_FALSE(feet.empty());
  const auto crs = vola::geo::describe_crs(feet, vola::geo::EpsgLookup::own_id_only);
  EXPECT_EQ(crs.name, "NAD83 / Mississippi West");
  EXPECT_EQ(crs.horizontal_unit, "US survey foot");
  EXPECT_FALSE(crs.epsg.has_value());  // no longer EPSG:26995
  // The same place in feet: EPSG:2255 is Mississippi West (ftUS).
  EXPECT_TRUE(vola::geo::same_crs(feet, "EPSG:2255"));
  EXPECT_TRUE(vola::geo::same_crs(keyed_projected_crs(26995, 9003, 9003), feet));  // heights in feet too: as x, y
  EXPECT_EQ(keyed_projected_crs(26995, 9001), "");   // metres: the code's own unit
  EXPECT_EQ(keyed_projected_crs(26995, 9102), "");   // degrees: not a length
  EXPECT_EQ(keyed_projected_crs(26995, 32632), "");  // a CRS code where a unit belongs (laspy_simple1_3.las)
  EXPECT_EQ(keyed_projected_crs(4326, 9003), "");    // not a projected CRS
  EXPECT_EQ(keyed_projected_crs(65000, 9003), "");   // no such code
  EXPECT_EQ(keyed_projected_crs(26910, 9001, 9001), "");

  // UTM in metres with heights in US survey feet: a compound CRS.
  const auto utm_feet = vola::geo::describe_crs(keyed_projected_crs(26910, 0, 9003));
  EXPECT_EQ(utm_feet.kind, "compound");
  EXPECT_EQ(utm_feet.horizontal_unit, "metre");
  EXPECT_EQ(utm_feet.vertical_unit, "US survey foot");
  EXPECT_EQ(utm_feet.epsg, std::optional<std::uint32_t>(26910));

  VOLA_REQUIRE_DATA(data);
  vola::io::LasReader reader((data / "las" / "pdal_mvk-thin.las").string());
  EXPECT_FALSE(reader.header().epsg.has_value());
  EXPECT_TRUE(vola::geo::same_crs(reader.header().wkt, feet));
}
