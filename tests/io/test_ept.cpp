// Entwine Point Tiles: datasets written here (ept.json, hierarchy files, nodes that are
// shared LAZ files or binary records made here) read back as the nodes' points, and each
// way a dataset can lie refused naming the file.
#include <gtest/gtest.h>

#include <fstream>
#include <string>
#include <tuple>

#include "io_test_data.hpp"
#include "test_support.hpp"
#include "vola/error.hpp"
#include "vola/io/ept.hpp"
#include "vola/io/input.hpp"

namespace {

using namespace vola_io_test;
namespace fs = std::filesystem;

void write_text(const fs::path& path, const std::string& text) {
  fs::create_directories(path.parent_path());
  std::ofstream(path, std::ios::binary) << text;
}

std::string ept_json(const std::string& type, std::uint64_t points, const std::string& schema = "[]") {
  return "{\"bounds\": [0, 0, 0, 8, 8, 8], \"dataType\": \"" + type +
         "\", \"hierarchyType\": \"json\", \"points\": " + std::to_string(points) + ", \"schema\": " + schema +
         ", \"span\": 128, \"srs\": {\"authority\": \"EPSG\", " + "\"horizontal\": \"32610\"}, \"version\": \"1.0.0\"}";
}

// The FormatError message of reading the dataset, or "" when it reads.
std::string read_error(const fs::path& ept) {
  try {
    vola::io::read_input(ept.string(), "auto", {});
  } catch (const vola::Error& e) {
    return e.what();
  }
  return "";
}

// Two nodes that are the same shared LAZ file, the second behind a subtree file (count -1):
// the points of the file twice, in node order, with its columns and the srs's EPSG code.
TEST(Ept, LaszipNodesReadAsTheirFilesInNodeOrder) {
  VOLA_REQUIRE_DATA(data);
  const fs::path laz = data / "laz" / "laspy_simple.laz";
  const vola::io::Input one = vola::io::read_input(laz.string(), "las", {});
  const std::uint64_t n = one.cloud.size();
  vola_test::TempDir dir;
  write_text(dir / "ept.json", ept_json("laszip", 2 * n));
  write_text(dir / "ept-hierarchy" / "0-0-0-0.json", "{\"0-0-0-0\": " + std::to_string(n) + ", \"1-1-0-1\": -1}");
  write_text(dir / "ept-hierarchy" / "1-1-0-1.json", "{\"1-1-0-1\": " + std::to_string(n) + ", \"2-3-1-2\": 0}");
  fs::create_directories(dir / "ept-data");
  fs::copy_file(laz, dir / "ept-data" / "0-0-0-0.laz");
  fs::copy_file(laz, dir / "ept-data" / "1-1-0-1.laz");
  const auto nodes = vola::io::ept_nodes((dir / "ept.json").string());
  ASSERT_EQ(nodes.size(), 2u);
  EXPECT_EQ(nodes[1].key, "1-1-0-1");
  const vola::io::Input in = vola::io::read_input((dir / "ept.json").string(), "auto", {});
  EXPECT_EQ(in.format, "ept");
  EXPECT_EQ(in.epsg, 32610u);
  ASSERT_EQ(in.cloud.size(), 2 * n);
  EXPECT_TRUE(std::equal(one.cloud.xyz.begin(), one.cloud.xyz.end(), in.cloud.xyz.begin()));
  EXPECT_TRUE(std::equal(one.cloud.xyz.begin(), one.cloud.xyz.end(), in.cloud.xyz.begin() + 3 * static_cast<long>(n)));
  ASSERT_EQ(in.cloud.attributes.size(), one.cloud.attributes.size());
  for (std::size_t a = 0; a < one.cloud.attributes.size(); ++a) {
    EXPECT_EQ(in.cloud.attributes[a].name, one.cloud.attributes[a].name);
    EXPECT_EQ(in.cloud.attributes[a].values.size(), 2 * n);
  }
  // A node whose file holds another count than the hierarchy states (PDAL's bad-pointcount).
  write_text(dir / "ept-hierarchy" / "1-1-0-1.json", "{\"1-1-0-1\": " + std::to_string(n - 1) + "}");
  EXPECT_NE(read_error(dir / "ept.json")
                .find("1-1-0-1.laz: holds " + std::to_string(n) + " points where the hierarchy states"),
            std::string::npos)
      << read_error(dir / "ept.json");
}

// Binary records as the schema lays them out: scaled integer coordinates, an unsigned
// intensity and a classification.
TEST(Ept, BinaryNodesFollowTheSchema) {
  vola_test::TempDir dir;
  const std::string schema =
      "[{\"name\": \"X\", \"size\": 4, \"type\": \"signed\", \"scale\": 0.01, \"offset\": 100},"
      " {\"name\": \"Y\", \"size\": 4, \"type\": \"signed\", \"scale\": 0.01},"
      " {\"name\": \"Z\", \"size\": 8, \"type\": \"float\"},"
      " {\"name\": \"Intensity\", \"size\": 2, \"type\": \"unsigned\"},"
      " {\"name\": \"Classification\", \"size\": 1, \"type\": \"unsigned\"}]";
  write_text(dir / "ept.json", ept_json("binary", 2, schema));
  write_text(dir / "ept-hierarchy" / "0-0-0-0.json", "{\"0-0-0-0\": 2}");
  Bytes records;
  for (const auto& [x, y, z, intensity, cls] :
       {std::tuple{150, -25, 7.5, 300, 2}, std::tuple{-100, 1000, -1.25, 65535, 6}}) {
    put<std::int32_t>(records, x);
    put<std::int32_t>(records, y);
    put<double>(records, z);
    put<std::uint16_t>(records, static_cast<std::uint16_t>(intensity));
    records.push_back(static_cast<std::uint8_t>(cls));
  }
  fs::create_directories(dir / "ept-data");
  vola_test::write_bytes(dir / "ept-data" / "0-0-0-0.bin", records);
  const vola::io::Input in = vola::io::read_input((dir / "ept.json").string(), "auto", {});
  EXPECT_EQ(in.cloud.xyz, (std::vector<double>{101.5, -0.25, 7.5, 99.0, 10.0, -1.25}));
  ASSERT_EQ(in.cloud.attributes.size(), 2u);
  EXPECT_EQ(in.cloud.attributes[0].name, "intensity");
  EXPECT_EQ(in.cloud.attributes[0].type, vola::ValueType::u16);
  EXPECT_EQ(in.cloud.attributes[0].values, (std::vector<double>{300, 65535}));
  EXPECT_EQ(in.cloud.attributes[1].name, "classification");
  EXPECT_EQ(in.cloud.attributes[1].reduction, vola::Reduction::majority);
  EXPECT_EQ(in.cloud.attributes[1].values, (std::vector<double>{2, 6}));
  // One byte short of the records the hierarchy states.
  records.pop_back();
  vola_test::write_bytes(dir / "ept-data" / "0-0-0-0.bin", records);
  EXPECT_NE(read_error(dir / "ept.json").find("0-0-0-0.bin: holds 37 bytes, not the 2 records of 19 bytes"),
            std::string::npos)
      << read_error(dir / "ept.json");
}

// Three binary nodes of one point each: the root (its cube the dataset's, 0..8), 1-0-0-0
// (0..4 along each axis) and 1-1-1-1 (4..8). A region inside the upper octant reads the
// root and 1-1-1-1 only; the bytes read say so.
TEST(Ept, ARegionReadsOnlyTheNodesWhoseCubeMeetsIt) {
  vola_test::TempDir dir;
  const std::string schema =
      "[{\"name\": \"X\", \"size\": 8, \"type\": \"float\"}, {\"name\": \"Y\", \"size\": 8, \"type\": \"float\"},"
      " {\"name\": \"Z\", \"size\": 8, \"type\": \"float\"}]";
  write_text(dir / "ept.json", ept_json("binary", 3, schema));
  write_text(dir / "ept-hierarchy" / "0-0-0-0.json", "{\"0-0-0-0\": 1, \"1-0-0-0\": 1, \"1-1-1-1\": 1}");
  const auto node = [&](const std::string& key, double at) {
    Bytes record;
    for (int a = 0; a < 3; ++a) put<double>(record, at);
    fs::create_directories(dir / "ept-data");
    vola_test::write_bytes(dir / "ept-data" / (key + ".bin"), record);
  };
  node("0-0-0-0", 1.0);
  node("1-0-0-0", 2.0);
  node("1-1-1-1", 6.0);
  const std::string ept = (dir / "ept.json").string();
  const vola::io::EptDataset dataset = vola::io::ept_dataset(ept);
  const auto nodes = vola::io::ept_nodes(ept);
  ASSERT_EQ(nodes.size(), 3u);
  EXPECT_EQ(vola::io::ept_node_bounds(dataset, nodes[0]), (std::array<double, 6>{0, 0, 0, 8, 8, 8}));
  EXPECT_EQ(vola::io::ept_node_bounds(dataset, nodes[1]), (std::array<double, 6>{0, 0, 0, 4, 4, 4}));
  EXPECT_EQ(vola::io::ept_node_bounds(dataset, nodes[2]), (std::array<double, 6>{4, 4, 4, 8, 8, 8}));

  const vola::io::Input all = vola::io::read_input(ept, "auto", {});
  EXPECT_EQ(all.cloud.xyz, (std::vector<double>{1, 1, 1, 2, 2, 2, 6, 6, 6}));
  EXPECT_EQ(all.bytes_total, 72u);
  ASSERT_TRUE(all.bytes_read);
  EXPECT_EQ(all.bytes_read(), 72u);

  vola::io::InputOptions options;
  options.region = vola::Box{{4.5, 4.5, 4.5}, {7, 7, 7}};
  const vola::io::Input window = vola::io::read_input(ept, "auto", options);
  EXPECT_EQ(window.cloud.xyz, (std::vector<double>{1, 1, 1, 6, 6, 6}));  // the root's point is not in it: the root is
  EXPECT_EQ(window.bytes_total, 72u);
  EXPECT_EQ(window.bytes_read(), 48u);
  // A region touching the face between the octants reads both (Entwine's cubes are closed).
  options.region = vola::Box{{4, 4, 4}, {4, 4, 4}};
  EXPECT_EQ(vola::io::read_input(ept, "auto", options).cloud.size(), 3u);
  // With the level too, the root alone.
  options.copc_level = 0;
  EXPECT_EQ(vola::io::read_input(ept, "auto", options).cloud.xyz, (std::vector<double>{1, 1, 1}));
}

TEST(Ept, LyingHierarchiesAreRefusedNamingTheFile) {
  vola_test::TempDir dir;
  const fs::path ept = dir / "ept.json";
  const fs::path root = dir / "ept-hierarchy" / "0-0-0-0.json";
  const std::string yz =
      "{\"name\": \"Y\", \"size\": 4, \"type\": \"float\"}, {\"name\": \"Z\", \"size\": 4, \"type\": \"float\"}]";
  write_text(ept, ept_json("binary", 10, "[{\"name\": \"X\", \"size\": 4, \"type\": \"float\"}, " + yz));
  const auto expect = [&](const std::string& hierarchy, const std::string& message) {
    write_text(root, hierarchy);
    const std::string error = read_error(ept);
    EXPECT_NE(error.find(message), std::string::npos) << hierarchy << " -> " << error;
    EXPECT_NE(error.find("ept-hierarchy"), std::string::npos) << error;
  };
  expect("{\"0-0-0-0\": 1, \"1-2-0-0\": 1}", "'1-2-0-0' lies outside an octree of its depth");
  expect("{\"0-0-0-0\": 1, \"1-0-0\": 1}", "'1-0-0' is not a node key D-X-Y-Z");
  expect("{\"0-0-0-0\": 11}", "the nodes hold more points than ept.json's 10");
  expect("{\"0-0-0-0\": 1.5}", "node 0-0-0-0: the count 1.5 is not an integer >= -1");
  expect("{\"0-0-0-0\": -1}", "a loop of hierarchy files");  // the root names itself as its subtree
  expect("[1, 2]", "a hierarchy file must be one JSON object");
  expect("{\"0-0-0-0\": ", "not valid JSON");
  // A hierarchy file too large to be one (sparse: no disk is spent) is refused unread.
  write_text(root, "{}");
  fs::resize_file(root, (std::uintmax_t{64} << 20) + 1);
  EXPECT_NE(read_error(ept).find("bytes of JSON, more than the 64 MiB"), std::string::npos) << read_error(ept);
  // A subtree file that is not there.
  write_text(root, "{\"0-0-0-0\": 1, \"1-0-0-0\": -1}");
  EXPECT_NE(read_error(ept).find("1-0-0-0.json"), std::string::npos) << read_error(ept);
  // Data vola does not decode, and a JSON file that is no EPT dataset.
  write_text(ept, ept_json("zstandard", 10));
  EXPECT_NE(read_error(ept).find("EPT data of type zstandard is not read by vola"), std::string::npos);
  write_text(root, "{\"0-0-0-0\": 1}");
  write_text(ept, ept_json("binary", 10, "[]"));
  EXPECT_NE(read_error(ept).find("the schema has no X dimension"), std::string::npos) << read_error(ept);
  write_text(
      ept, ept_json("binary", 10, "[{\"name\": \"X\", \"size\": 4, \"type\": \"float\", \"scale\": \"0.01\"}, " + yz));
  EXPECT_NE(read_error(ept).find("scale must be a number"), std::string::npos) << read_error(ept);
  write_text(ept, "{\"type\": \"FeatureCollection\"}");
  EXPECT_NE(read_error(ept).find("not an EPT ept.json: no \"dataType\""), std::string::npos) << read_error(ept);
}

}  // namespace
