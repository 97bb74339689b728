// KITTI velodyne reader: the shared scans against EXPECTED.txt and a slow reader; the
// reference's payload; sizes that are not whole records.
#include <gtest/gtest.h>

#include <fstream>

#include "io_test_data.hpp"
#include "test_support.hpp"
#include "vola/io/input.hpp"
#include "vola/io/kitti.hpp"

namespace {

using namespace vola_io_test;

TEST(Kitti, SharedScansMatchExpectedAndASlowReader) {
  VOLA_REQUIRE_DATA(data);
  auto files = files_ending(data / "kitti", ".bin");
  ASSERT_GE(files.size(), 3u);
  for (const auto& path : files) {
    SCOPED_TRACE(path.string());
    const std::string relative = path.lexically_relative(data).string();
    const std::string line = expected_line(data, relative);
    vola::io::InputOptions options;
    options.payload = true;
    const vola::io::Input in = vola::io::read_input(path.string(), "auto", options);
    EXPECT_EQ(in.format, "kitti");
    // EXPECTED.txt: "n= N min [x, y, z, r] max [x, y, z, r]", bounds rounded to 2 decimals
    // (then printed as float32: 2.890000104904175 where the smallest x is 2.889).
    EXPECT_EQ(in.cloud.size(), expected_integer(line, "n= ").value());
    const auto min = expected_numbers(line, "min").value(), max = expected_numbers(line, "max").value();
    const vola::Box box = in.cloud.bounds();
    for (std::size_t a = 0; a < 3; ++a) {
      EXPECT_NEAR(box.min[a], min[a], 0.0051);
      EXPECT_NEAR(box.max[a], max[a], 0.0051);
    }
    ASSERT_EQ(in.cloud.attributes.size(), 1u);
    const auto& reflectance = in.cloud.attributes[0];
    EXPECT_EQ(reflectance.name, "reflectance");
    EXPECT_NEAR(*std::min_element(reflectance.values.begin(), reflectance.values.end()), min[3], 0.0051);
    EXPECT_NEAR(*std::max_element(reflectance.values.begin(), reflectance.values.end()), max[3], 0.0051);

    // Slow reader: four floats at a time from a stream.
    std::ifstream slow(path, std::ios::binary);
    float record[4];
    std::size_t i = 0;
    while (slow.read(reinterpret_cast<char*>(record), sizeof record)) {
      ASSERT_LT(i, in.cloud.size());
      for (std::size_t a = 0; a < 3; ++a) ASSERT_EQ(in.cloud.xyz[3 * i + a], record[a]) << i;
      ASSERT_EQ(reflectance.values[i], record[3]) << i;
      const std::uint64_t grey = vola::io::kitti_reflectance_byte(record[3]);
      ASSERT_EQ(in.cloud.payload[i], grey | grey << 8 | grey << 16) << i;
      ++i;
    }
    EXPECT_EQ(i, in.cloud.size());
  }
}

TEST(Kitti, ReflectanceBytesAreTheReferences) {
  // kitti2vola.py's parse_bin run under NumPy 1.24 on these float32 reflectances.
  const std::pair<float, int> cases[] = {{-1.0f, 0},   {-0.2f, 0},   {-0.19999f, 0}, {0.0f, 42},   {0.01f, 44},
                                         {0.1f, 63},   {0.2f, 85},   {0.25f, 95},    {0.3f, 106},  {0.33f, 112},
                                         {0.5f, 148},  {0.6f, 170},  {0.7f, 191},    {0.75f, 201}, {0.8f, 212},
                                         {0.9f, 233},  {0.99f, 252}, {1.0f, 255},    {2.0f, 255}};
  for (const auto& [reflectance, byte] : cases) EXPECT_EQ(vola::io::kitti_reflectance_byte(reflectance), byte) << reflectance;
}

TEST(Kitti, SizesThatAreNotWholeRecordsAreFormatErrors) {
  Bytes bytes;
  for (float v : {1.0f, 2.0f, 3.0f, 0.5f, -1.0f, -2.0f, -3.0f, 0.25f}) put<float>(bytes, v);
  const auto cloud = vola::io::parse_kitti(bytes, "two.bin");
  EXPECT_EQ(cloud.xyz, (std::vector<double>{1, 2, 3, -1, -2, -3}));
  EXPECT_EQ(cloud.attributes[0].values, (std::vector<double>{0.5, 0.25}));
  EXPECT_TRUE(cloud.payload.empty());
  for (std::size_t n = 1; n < bytes.size(); ++n) {
    if (n % 16 == 0) continue;
    const Bytes cut(bytes.begin(), bytes.begin() + static_cast<std::ptrdiff_t>(n));
    const auto error = vola_test::format_error_of([&] { vola::io::parse_kitti(cut, "cut.bin"); });
    ASSERT_TRUE(error) << n;
    EXPECT_EQ(error->offset(), n / 16 * 16);
    EXPECT_NE(error->cause().find("16-byte records"), std::string::npos);
  }
  EXPECT_EQ(vola::io::parse_kitti({}, "empty.bin").size(), 0u);
}

// nuScenes' devkit reads a sweep as np.fromfile(f, np.float32).reshape(-1, 5): x y z
// intensity ring. Four such records are 80 bytes, five whole KITTI records too: only the
// name (.pcd.bin) tells them apart, and as KITTI they would read as five wrong points.
TEST(Kitti, NuscenesSweepsAreFiveFloatsAPoint) {
  Bytes bytes;
  for (float v : {1.0f, 2.0f, 3.0f, 17.0f, 0.0f,  -1.0f, -2.0f, -3.0f, 300.0f, 31.0f,
                  4.5f, 5.5f, 6.5f, 0.0f,  12.0f, 7.0f,  8.0f,  9.0f,  255.0f, 1e9f})
    put<float>(bytes, v);
  vola_test::TempDir dir;
  const auto path = dir / "n008-2018-08-01-15-16-36-0400__LIDAR_TOP__1533151603547590.pcd.bin";
  vola_test::write_bytes(path, bytes);
  EXPECT_TRUE(vola::io::is_nuscenes_sweep(path.string()));
  EXPECT_FALSE(vola::io::is_nuscenes_sweep((dir / "000000.bin").string()));
  vola::io::InputOptions options;
  options.payload = true;
  const vola::io::Input in = vola::io::read_input(path.string(), "auto", options);
  EXPECT_EQ(in.format, "kitti");
  EXPECT_EQ(in.cloud.xyz, (std::vector<double>{1, 2, 3, -1, -2, -3, 4.5, 5.5, 6.5, 7, 8, 9}));
  ASSERT_EQ(in.cloud.attributes.size(), 2u);
  EXPECT_EQ(in.cloud.attributes[0].name, "intensity");
  EXPECT_EQ(in.cloud.attributes[0].values, (std::vector<double>{17, 300, 0, 255}));
  EXPECT_EQ(in.cloud.attributes[1].name, "ring");
  EXPECT_EQ(in.cloud.attributes[1].values, (std::vector<double>{0, 31, 12, 255}));  // 1e9 is no ring: 255
  EXPECT_EQ(in.cloud.payload, (std::vector<std::uint64_t>{17 * 0x010101u, 255 * 0x010101u, 0, 255 * 0x010101u}));
  // The same bytes as KITTI: five records, as the size allows.
  EXPECT_EQ(vola::io::parse_kitti(bytes, "000000.bin").size(), 4u * 20 / 16);
  for (std::size_t n = 1; n < bytes.size(); ++n) {
    if (n % 20 == 0) continue;
    const Bytes cut(bytes.begin(), bytes.begin() + static_cast<std::ptrdiff_t>(n));
    const auto error = vola_test::format_error_of([&] { vola::io::parse_nuscenes(cut, "cut.pcd.bin"); });
    ASSERT_TRUE(error) << n;
    EXPECT_EQ(error->offset(), n / 20 * 20);
    EXPECT_NE(error->cause().find("20-byte records"), std::string::npos);
  }
  // Lyft names its sweeps plain .bin: --format nuscenes reads any name, and KITTI's size
  // error points there when the size is a whole number of 20-byte records.
  const auto lyft = dir / "host-a017_lidar1_1236118886501000046.bin";
  vola_test::write_bytes(lyft, Bytes(bytes.begin(), bytes.begin() + 60));  // three records
  const vola::io::Input as_nuscenes = vola::io::read_input(lyft.string(), "nuscenes", {});
  EXPECT_EQ(as_nuscenes.format, "nuscenes");
  EXPECT_EQ(as_nuscenes.cloud.xyz, (std::vector<double>{1, 2, 3, -1, -2, -3, 4.5, 5.5, 6.5}));
  const auto error = vola_test::format_error_of([&] { vola::io::read_input(lyft.string(), "auto", {}); });
  ASSERT_TRUE(error);
  EXPECT_NE(error->cause().find("--format nuscenes"), std::string::npos) << error->cause();
}

}  // namespace
