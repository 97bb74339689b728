// The E57 reader on files written here (tests/io/e57_test_file.hpp): every field type,
// bit widths that cross bytes and packets, spherical points, poses, invalid points, scans
// with other fields, and each way a file can be damaged or lie, refused naming the file.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>

#include "e57_test_file.hpp"
#include "test_support.hpp"
#include "vola/error.hpp"
#include "vola/io/e57.hpp"
#include "vola/io/input.hpp"

namespace {

using vola_io_test::E57TestField;
using vola_io_test::E57TestScan;
namespace fs = std::filesystem;

E57TestField floats(const std::string& name, std::vector<double> values, bool single = false) {
  return {name, "Float", single, 0, 0, 1.0, 0.0, std::move(values)};
}

E57TestField integers(const std::string& name, std::int64_t lo, std::int64_t hi, std::vector<double> values) {
  return {name, "Integer", false, lo, hi, 1.0, 0.0, std::move(values)};
}

E57TestField scaled(const std::string& name, std::int64_t lo, std::int64_t hi, double scale, double offset,
                    std::vector<double> values) {
  return {name, "ScaledInteger", false, lo, hi, scale, offset, std::move(values)};
}

struct Written {
  vola_test::TempDir dir;
  fs::path path;
  explicit Written(const std::vector<E57TestScan>& scans, const std::string& name = "scan.e57") : path(dir / name) {
    vola_test::write_bytes(path, vola_io_test::e57_test_file(scans));
  }
};

std::string read_error(const fs::path& path) {
  try {
    vola::io::read_input(path.string(), "auto", {});
  } catch (const vola::Error& e) {
    return e.what();
  }
  return "";
}

const vola::PointAttribute* column(const vola::io::Input& in, const std::string& name) {
  for (const auto& a : in.cloud.attributes)
    if (a.name == name) return &a;
  return nullptr;
}

// 2500 records in packets of 7: a 10-bit scaled coordinate, a 3-bit integer and a 17-bit
// one cross bytes and packets at every phase; single and double floats; 8-bit colours.
TEST(E57, EveryFieldTypeReadsBackAcrossPackets) {
  const std::size_t n = 2500;
  std::vector<double> x, y, z, small, wide, intensity, red, green, blue;
  for (std::size_t i = 0; i < n; ++i) {
    x.push_back(-0.5 + 0.001 * static_cast<double>(i % 1001));  // ScaledInteger -500..500 at 1e-3
    y.push_back(0.25 * static_cast<double>(i));                 // double
    z.push_back(static_cast<double>(static_cast<float>(0.1 * static_cast<double>(i))));  // single
    small.push_back(static_cast<double>(i % 8));
    wide.push_back(-70000.0 + static_cast<double>((i * 37) % 131072));
    intensity.push_back(static_cast<double>(i % 4096));
    red.push_back(static_cast<double>(i % 256));
    green.push_back(static_cast<double>((i * 7) % 256));
    blue.push_back(255.0);
  }
  E57TestScan scan;
  scan.records_per_packet = 7;
  scan.fields = {scaled("cartesianX", -500, 500, 1e-3, 0.0, x),
                 floats("cartesianY", y),
                 floats("cartesianZ", z, true),
                 integers("returnCount", 0, 7, small),
                 integers("las:pointSourceId", -70000, 61071, wide),
                 integers("intensity", 0, 4095, intensity),
                 integers("colorRed", 0, 255, red),
                 integers("colorGreen", 0, 255, green),
                 integers("colorBlue", 0, 255, blue)};
  const Written file({scan});
  const vola::io::Input in = vola::io::read_input(file.path.string(), "auto", {});
  EXPECT_EQ(in.format, "e57");
  ASSERT_EQ(in.cloud.size(), n);
  for (std::size_t i = 0; i < n; ++i) {
    ASSERT_NEAR(in.cloud.xyz[3 * i], x[i], 1e-12) << i;
    ASSERT_EQ(in.cloud.xyz[3 * i + 1], y[i]) << i;
    ASSERT_EQ(in.cloud.xyz[3 * i + 2], z[i]) << i;
  }
  ASSERT_NE(column(in, "number_of_returns"), nullptr);
  EXPECT_EQ(column(in, "number_of_returns")->values, small);
  EXPECT_EQ(column(in, "number_of_returns")->type, vola::ValueType::u8);
  ASSERT_NE(column(in, "point_source_id"), nullptr);
  EXPECT_EQ(column(in, "point_source_id")->values, wide);
  EXPECT_EQ(column(in, "point_source_id")->type, vola::ValueType::i32);
  EXPECT_EQ(column(in, "intensity")->values, intensity);
  EXPECT_EQ(column(in, "intensity")->type, vola::ValueType::u16);
  EXPECT_EQ(column(in, "red")->values, red);
  EXPECT_EQ(column(in, "green")->values, green);
  EXPECT_EQ(column(in, "blue")->values, blue);
  // The reference's payload: R, G, B in bytes 0..2.
  vola::io::InputOptions payload;
  payload.payload = true;
  const vola::io::Input p = vola::io::read_input(file.path.string(), "auto", payload);
  ASSERT_EQ(p.cloud.payload.size(), n);
  EXPECT_EQ(p.cloud.payload[9], 9u | (63u << 8) | (255u << 16));
  // The summary is the XML's.
  const vola::io::E57Summary summary = vola::io::e57_summary(file.path.string());
  ASSERT_EQ(summary.scans.size(), 1u);
  EXPECT_EQ(summary.scans[0].records, n);
  EXPECT_EQ(summary.scans[0].fields.size(), 9u);
  EXPECT_EQ(summary.library, "vola tests");
}

// Spherical points (range, azimuth, elevation) become cartesian, the scanner's invalid
// points are left out and counted, and the pose turns and moves the scan.
TEST(E57, SphericalPointsInvalidStatesAndPoses) {
  const double pi = std::numbers::pi;
  E57TestScan scan;
  scan.fields = {floats("sphericalRange", {2.0, 5.0, 3.0, 1.0}), floats("sphericalAzimuth", {0.0, 1.0, pi / 2, 0.0}),
                 floats("sphericalElevation", {0.0, 0.5, pi / 6, 0.0}),
                 integers("sphericalInvalidState", 0, 2, {0, 2, 0, 1})};
  // A quarter turn about z (w = cos 45, z = sin 45), then a move by (10, 20, 30).
  const double h = std::sqrt(0.5);
  scan.pose = std::array<double, 7>{h, 0, 0, h, 10, 20, 30};
  const Written file({scan});
  const vola::io::Input in = vola::io::read_input(file.path.string(), "auto", {});
  ASSERT_EQ(in.cloud.size(), 2u);
  EXPECT_EQ(in.not_finite, 2u);  // the points marked 1 (direction only) and 2 (no return)
  // Point 0: (2, 0, 0) -> turned (0, 2, 0) -> (10, 22, 30).
  EXPECT_NEAR(in.cloud.xyz[0], 10.0, 1e-12);
  EXPECT_NEAR(in.cloud.xyz[1], 22.0, 1e-12);
  EXPECT_NEAR(in.cloud.xyz[2], 30.0, 1e-12);
  // Point 2: r 3 at azimuth 90 degrees, elevation 30: (0, 3 cos 30, 1.5) -> turned (-3 cos 30, 0, 1.5).
  EXPECT_NEAR(in.cloud.xyz[3], 10.0 - 3.0 * std::cos(pi / 6), 1e-12);
  EXPECT_NEAR(in.cloud.xyz[4], 20.0, 1e-12);
  EXPECT_NEAR(in.cloud.xyz[5], 31.5, 1e-12);
  const auto summary = vola::io::e57_summary(file.path.string());
  EXPECT_TRUE(summary.scans[0].has_pose);
}

// A pose missing a component (E2807 requires w x y z and x y z) took it from the identity:
// a rotation of x alone became (1, 1, 0, 0) / sqrt 2, a quarter turn about x.
TEST(E57, APoseMissingAComponentIsRefusedNamingTheScan) {
  E57TestScan scan;
  scan.name = "station 4";
  scan.fields = {floats("cartesianX", {1}), floats("cartesianY", {2}), floats("cartesianZ", {3})};
  scan.pose_xml = "<pose type=\"Structure\"><rotation type=\"Structure\"><x type=\"Float\">1</x></rotation></pose>";
  const Written rotation({scan});
  EXPECT_NE(read_error(rotation.path).find("scan 'station 4': its pose's rotation has no w"), std::string::npos)
      << read_error(rotation.path);
  scan.pose_xml =
      "<pose type=\"Structure\"><translation type=\"Structure\"><x type=\"Float\">1</x>"
      "<y type=\"Float\">2</y></translation></pose>";
  const Written translation({scan});
  EXPECT_NE(read_error(translation.path).find("its pose's translation has no z"), std::string::npos)
      << read_error(translation.path);
}

// Two scans: the columns are the fields both have; the points of both, in file order.
TEST(E57, ScansWithOtherFieldsKeepTheColumnsTheyShare) {
  E57TestScan a, b;
  a.name = "a";
  a.fields = {floats("cartesianX", {1, 2}), floats("cartesianY", {0, 0}), floats("cartesianZ", {0, 0}),
              integers("intensity", 0, 255, {10, 20}), floats("timeStamp", {0.5, 0.75})};
  b.name = "b";
  b.fields = {floats("cartesianX", {3}), floats("cartesianY", {0}), floats("cartesianZ", {0}),
              floats("intensity", {0.25}, true)};
  const Written file({a, b});
  const vola::io::Input in = vola::io::read_input(file.path.string(), "auto", {});
  ASSERT_EQ(in.cloud.size(), 3u);
  EXPECT_EQ(in.cloud.xyz[6], 3.0);
  ASSERT_EQ(in.cloud.attributes.size(), 1u);
  EXPECT_EQ(in.cloud.attributes[0].name, "intensity");
  EXPECT_EQ(in.cloud.attributes[0].type, vola::ValueType::f64);  // u8 in one scan, f32 in the other
  EXPECT_EQ(in.cloud.attributes[0].values, (std::vector<double>{10, 20, 0.25}));
}

// coordinateMetadata: "EPSG:N" is a code, other text a definition for PROJ to read.
TEST(E57, CoordinateMetadataIsTheCrs) {
  E57TestScan scan;
  scan.fields = {floats("cartesianX", {1}), floats("cartesianY", {2}), floats("cartesianZ", {3})};
  vola_test::TempDir dir;
  const fs::path path = dir / "crs.e57";
  vola_test::write_bytes(path, vola_io_test::e57_test_file({scan}, "EPSG:32633"));
  vola::io::Input in = vola::io::read_input(path.string(), "auto", {});
  EXPECT_EQ(in.epsg, 32633u);
  EXPECT_TRUE(in.wkt.empty());
  const std::string wkt = "GEOGCRS[\"WGS 84\",DATUM[\"World Geodetic System 1984\"]]";
  vola_test::write_bytes(path, vola_io_test::e57_test_file({scan}, "  " + wkt + "\n"));
  in = vola::io::read_input(path.string(), "auto", {});
  EXPECT_FALSE(in.epsg);
  EXPECT_EQ(in.wkt, wkt);
  EXPECT_EQ(vola::io::e57_summary(path.string()).crs, wkt);
  vola_test::write_bytes(path, vola_io_test::e57_test_file({scan}));
  EXPECT_TRUE(vola::io::read_input(path.string(), "auto", {}).wkt.empty());
}

TEST(E57, DamagedAndLyingFilesAreRefusedNamingTheFile) {
  E57TestScan scan;
  scan.fields = {floats("cartesianX", {1, 2, 3}), floats("cartesianY", {4, 5, 6}), floats("cartesianZ", {7, 8, 9})};
  const std::vector<std::uint8_t> good = vola_io_test::e57_test_file({scan});
  vola_test::TempDir dir;
  const fs::path path = dir / "bad.e57";
  const auto expect = [&](const std::vector<std::uint8_t>& bytes, const std::string& message) {
    vola_test::write_bytes(path, bytes);
    const std::string error = read_error(path);
    EXPECT_NE(error.find(message), std::string::npos) << error;
    EXPECT_NE(error.find("bad.e57"), std::string::npos) << error;
  };
  std::vector<std::uint8_t> b = good;
  b[100] ^= 1;
  expect(b, "the checksum of page 0 does not match its bytes");
  b.assign(good.begin(), good.end() - 10);  // cut short
  expect(b, "not whole pages");
  b = good;
  b[0] = 'X';
  expect(b, "not an E57 file");
  b = good;
  b[8] = 2;  // major version 2: the page's checksum is written again below
  {
    const std::uint32_t crc = vola_io_test::e57_test_crc32c(b.data(), 1020);
    for (int k = 0; k < 4; ++k) b[1020 + static_cast<std::size_t>(k)] = static_cast<std::uint8_t>(crc >> (24 - 8 * k));
  }
  expect(b, "E57 version 2.0");
  // A recordCount the section cannot hold.
  E57TestScan lying = scan;
  lying.stated_records = 1000000;
  expect(vola_io_test::e57_test_file({lying}), "claims 1000000 records");
  // A field whose stream ends before its records do (records stated within the section's size).
  lying.stated_records = 4;
  expect(vola_io_test::e57_test_file({lying}), "field cartesianX ends after 3 of its 4 records");
  // No coordinates.
  E57TestScan flat;
  flat.fields = {floats("intensity", {1})};
  expect(vola_io_test::e57_test_file({flat}), "has neither cartesianX/Y/Z nor sphericalRange");
  // Fields of a kind the prototype may not hold.
  E57TestScan odd = scan;
  odd.fields[0].type = "Structure";
  expect(vola_io_test::e57_test_file({odd}), "field cartesianX of type \"Structure\"");
  E57TestScan backwards = scan;
  backwards.fields.push_back(integers("intensity", 5, 1, {1, 2, 3}));
  expect(vola_io_test::e57_test_file({backwards}), "maximum below minimum");
}

}  // namespace
