// ROS maps (map_server YAML + PGM) against a cell-by-cell reading of the rule, done the
// slow way: every column's voxels looked at one by one, centres compared with the band.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <random>
#include <set>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "test_support.hpp"
#include "vola/error.hpp"
#include "vola/io/png_image.hpp"
#include "vola/io/ros_map.hpp"

namespace {

using vola::Voxel;
using vola::io::MapVoxels;

struct Pgm {
  std::uint32_t width = 0, height = 0;
  std::vector<std::uint8_t> pixels;  // row 0 the top
};

Pgm read_pgm(const std::filesystem::path& path) {
  const std::vector<std::uint8_t> bytes = vola_test::read_bytes(path);
  std::istringstream header(std::string(bytes.begin(), bytes.begin() + std::min<std::size_t>(bytes.size(), 64)));
  std::string magic;
  unsigned maxval = 0;
  Pgm pgm;
  header >> magic >> pgm.width >> pgm.height >> maxval;
  EXPECT_EQ(magic, "P5");
  EXPECT_EQ(maxval, 255u);
  const std::size_t start = static_cast<std::size_t>(header.tellg()) + 1;  // one whitespace after maxval
  pgm.pixels.assign(bytes.begin() + static_cast<std::ptrdiff_t>(start), bytes.end());
  EXPECT_EQ(pgm.pixels.size(), std::size_t{pgm.width} * pgm.height);
  return pgm;
}

std::map<std::string, std::string> read_yaml(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::map<std::string, std::string> fields;
  std::string line;
  while (std::getline(in, line)) {
    const auto colon = line.find(": ");
    if (colon != std::string::npos) fields[line.substr(0, colon)] = line.substr(colon + 2);
  }
  return fields;
}

// What a cell shows, by the rule read literally.
std::uint8_t expected_pixel(const MapVoxels& map, std::uint32_t x, std::uint32_t y, double z_min, double z_max) {
  const auto centre = [&](const Voxel& v) { return map.frame.origin[2] + (v.z + 0.5) * map.frame.voxel_size; };
  bool occupied_in_band = false, free_in_band = false, occupied_below = false;
  for (const Voxel& v : map.occupied)
    if (v.x == x && v.y == y) {
      occupied_in_band |= centre(v) >= z_min && centre(v) <= z_max;
      occupied_below |= centre(v) < z_min;
    }
  for (const Voxel& v : map.free)
    if (v.x == x && v.y == y) free_in_band |= centre(v) >= z_min && centre(v) <= z_max;
  if (occupied_in_band) return 0;
  if (map.free.empty() ? occupied_below : free_in_band) return 254;
  return 205;
}

MapVoxels random_map(std::uint64_t seed, bool with_free) {
  std::mt19937_64 random(seed);
  std::uniform_int_distribution<std::uint32_t> xy(3, 20), z(5, 12);
  MapVoxels map;
  map.frame.origin = {-3.5, 100.25, 7.0};
  map.frame.voxel_size = 0.25;
  std::map<std::array<std::uint32_t, 3>, bool> cells;  // true: occupied
  for (int i = 0; i < 300; ++i) cells[{xy(random), xy(random), z(random)}] = !with_free || random() % 3 != 0;
  for (const auto& [cell, occupied] : cells)
    (occupied ? map.occupied : map.free).push_back({cell[0], cell[1], cell[2]});
  return map;
}

TEST(RosMap, EveryCellFollowsTheRule) {
  vola_test::TempDir dir;
  for (std::uint64_t seed = 1; seed <= 6; ++seed) {
    const bool with_free = seed % 2 == 0;
    const MapVoxels map = random_map(seed, with_free);
    // Bands whose ends fall on a voxel centre (8.625 = layer 6's), between centres, and
    // past the map's top.
    for (const auto& [z_min, z_max] : {std::pair{8.625, 9.5}, std::pair{8.7, 9.0}, std::pair{9.3, 100.0}}) {
      const auto yaml = dir / ("map" + std::to_string(seed) + ".yaml");
      const auto report = vola::io::write_ros_map(map, yaml.string(), {z_min, z_max});
      const Pgm pgm = read_pgm(dir / ("map" + std::to_string(seed) + ".pgm"));
      std::uint32_t x0 = ~0u, y0 = ~0u, x1 = 0, y1 = 0;
      for (const auto* list : {&map.occupied, &map.free})
        for (const Voxel& v : *list)
          x0 = std::min(x0, v.x), y0 = std::min(y0, v.y), x1 = std::max(x1, v.x), y1 = std::max(y1, v.y);
      ASSERT_EQ(pgm.width, x1 - x0 + 1);
      ASSERT_EQ(pgm.height, y1 - y0 + 1);
      std::uint64_t counts[3] = {0, 0, 0};
      for (std::uint32_t row = 0; row < pgm.height; ++row)
        for (std::uint32_t col = 0; col < pgm.width; ++col) {
          const std::uint8_t want = expected_pixel(map, x0 + col, y1 - row, z_min, z_max);
          ASSERT_EQ(pgm.pixels[std::size_t{row} * pgm.width + col], want)
              << "seed " << seed << " cell " << col << "," << row;
          ++counts[want == 0 ? 0 : want == 254 ? 1 : 2];
        }
      EXPECT_EQ(report.occupied, counts[0]);
      EXPECT_EQ(report.free, counts[1]);
      EXPECT_EQ(report.unknown, counts[2]);
      EXPECT_GT(counts[0] + counts[1], 0u);
      EXPECT_EQ(report.free_from_ground, !with_free);

      const auto fields = read_yaml(yaml);
      EXPECT_EQ(fields.at("image"), "map" + std::to_string(seed) + ".pgm");
      EXPECT_EQ(fields.at("mode"), "trinary");
      EXPECT_EQ(fields.at("resolution"), "0.25");
      // The image's lower-left corner: the lowest column's corner in world coordinates.
      // Numbers as YAML floats, with a point (PyYAML reads "5e+05" or "-3" otherwise).
      const std::string origin = fields.at("origin");
      double ox = 0, oy = 0, oz = 1;
      ASSERT_EQ(std::sscanf(origin.c_str(), "[%lf, %lf, %lf]", &ox, &oy, &oz), 3) << origin;
      EXPECT_EQ(ox, -3.5 + 0.25 * x0);
      EXPECT_EQ(oy, 100.25 + 0.25 * y0);
      EXPECT_EQ(oz, 0.0);
      EXPECT_EQ(std::count(origin.begin(), origin.end(), '.'), 3) << origin;
      EXPECT_EQ(fields.at("negate"), "0");
      EXPECT_EQ(fields.at("occupied_thresh"), "0.65");
      EXPECT_EQ(fields.at("free_thresh"), "0.196");
    }
  }
}

TEST(RosMap, BandsThatCannotBeAreRefusedNamingTheOption) {
  vola_test::TempDir dir;
  const MapVoxels map = random_map(1, false);
  const auto refusal = [&](double z_min, double z_max) {
    try {
      vola::io::write_ros_map(map, (dir / "m.yaml").string(), {z_min, z_max});
    } catch (const vola::OptionError& e) {
      EXPECT_EQ(e.option(), "band");
      return std::string(e.what());
    }
    return std::string("written");
  };
  EXPECT_NE(refusal(2.0, 1.0).find("upside down"), std::string::npos);
  EXPECT_NE(refusal(NAN, 1.0).find("finite"), std::string::npos);
  // Between two layers' centres (8.375 and 8.625), and below the map in another unit.
  EXPECT_NE(refusal(8.4, 8.6).find(
                "holds no voxel centre of the map: its layers are 0.25 apart, centred from z = 8.375 to 10.125"),
            std::string::npos)
      << refusal(8.4, 8.6);
  EXPECT_NE(refusal(0.1, 1.5).find("holds no voxel centre"), std::string::npos);
  EXPECT_FALSE(std::filesystem::exists(dir / "m.yaml"));
  EXPECT_FALSE(std::filesystem::exists(dir / "m.pgm"));
}

}  // namespace

namespace {

void write_text(const std::filesystem::path& path, const std::string& text) {
  std::ofstream(path, std::ios::binary) << text;
}

std::set<std::array<std::uint32_t, 3>> voxel_set(const std::vector<Voxel>& voxels) {
  std::set<std::array<std::uint32_t, 3>> out;
  for (const Voxel& v : voxels) out.insert({v.x, v.y, v.z});
  return out;
}

}  // namespace

// What vola writes reads back: the occupied cells, on the map's grid, as one layer or as
// columns of map_height.
TEST(RosMap, WrittenMapsReadBackCellForCell) {
  vola_test::TempDir dir;
  const MapVoxels map = random_map(3, true);
  const auto yaml = (dir / "m.yaml").string();
  vola::io::write_ros_map(map, yaml, {8.625, 9.5});
  const Pgm pgm = read_pgm(dir / "m.pgm");
  std::uint32_t x0 = ~0u, y0 = ~0u;
  for (const auto* list : {&map.occupied, &map.free})
    for (const Voxel& v : *list) x0 = std::min(x0, v.x), y0 = std::min(y0, v.y);
  std::set<std::array<std::uint32_t, 3>> expected;
  for (std::uint32_t row = 0; row < pgm.height; ++row)
    for (std::uint32_t col = 0; col < pgm.width; ++col)
      if (pgm.pixels[std::size_t{row} * pgm.width + col] == 0) expected.insert({col, pgm.height - 1 - row, 0});
  ASSERT_FALSE(expected.empty());
  const vola::io::VoxelGrid one = vola::io::read_ros_map(yaml, 0.0);
  EXPECT_EQ(voxel_set(one.voxels), expected);
  EXPECT_EQ(one.voxel_size, 0.25);
  EXPECT_EQ(one.origin, (vola::Point{-3.5 + 0.25 * x0, 100.25 + 0.25 * y0, 0.0}));
  EXPECT_TRUE(one.fixed_voxel_size);
  const vola::io::VoxelGrid tall = vola::io::read_ros_map(yaml, 0.6);  // 0.6 / 0.25: three layers
  std::set<std::array<std::uint32_t, 3>> columns;
  for (const auto& c : expected)
    for (std::uint32_t k = 0; k < 3; ++k) columns.insert({c[0], c[1], k});
  EXPECT_EQ(voxel_set(tall.voxels), columns);
}

// Maps as map_server reads them: text (P2) and 16-bit PGMs, negate, thresholds, raw mode,
// lists as "- item" lines, quotes and comments.
TEST(RosMap, MapServerVariantsRead) {
  vola_test::TempDir dir;
  // 3 x 2 pixels, row 0 the top: 0 (black) is occupied, 254 free, 205 unknown, 100 grey.
  write_text(dir / "text.pgm", "P2\n# a comment\n3 2\n255\n0 254 205\n100 0 254\n");
  write_text(dir / "a.yaml",
             "image: \"text.pgm\"  # the picture\nresolution: 0.5\norigin:\n  - 1.0\n  - -2.0\n  - 0.0\n");
  EXPECT_EQ(
      voxel_set(vola::io::read_ros_map((dir / "a.yaml").string(), 0).voxels),
      (std::set<std::array<std::uint32_t, 3>>{{0, 1, 0}, {1, 0, 0}}));  // the zeros; 100 is p = 0.61, not above 0.65
  write_text(dir / "b.yaml", "image: text.pgm\nresolution: 0.5\norigin: [1.0, -2.0, 0.0]\noccupied_thresh: 0.5\n");
  EXPECT_EQ(vola::io::read_ros_map((dir / "b.yaml").string(), 0).voxels.size(), 3u);  // 100 is p = 0.61 > 0.5
  write_text(dir / "c.yaml", "image: text.pgm\nresolution: 0.5\norigin: [1.0, -2.0, 0.0]\nnegate: 1\n");
  EXPECT_EQ(voxel_set(vola::io::read_ros_map((dir / "c.yaml").string(), 0).voxels),
            (std::set<std::array<std::uint32_t, 3>>{{1, 1, 0}, {2, 1, 0}, {2, 0, 0}}));  // 254 and 205 are p > 0.65
  std::string wide = "P5\n2 1\n65535\n";
  wide += std::string("\x00\x00\xff\xff", 4);  // black, white
  write_text(dir / "wide.pgm", wide);
  write_text(dir / "d.yaml", "image: wide.pgm\nresolution: 1\norigin: [0, 0, 0]\n");
  EXPECT_EQ(voxel_set(vola::io::read_ros_map((dir / "d.yaml").string(), 0).voxels),
            (std::set<std::array<std::uint32_t, 3>>{{0, 0, 0}}));
  std::string raw = "P5\n3 1\n255\n";
  raw += std::string("\x64\x00\xff", 3);  // 100 %, 0 %, unknown
  write_text(dir / "raw.pgm", raw);
  write_text(dir / "e.yaml", "image: raw.pgm\nmode: raw\nresolution: 1\norigin: [0, 0, 0]\n");
  EXPECT_EQ(voxel_set(vola::io::read_ros_map((dir / "e.yaml").string(), 0).voxels),
            (std::set<std::array<std::uint32_t, 3>>{{0, 0, 0}}));
  // One flow mapping, as yaml.dump(default_flow_style=True) writes it, wrapped over lines.
  write_text(dir / "f.yaml", "{image: text.pgm, resolution: 0.5,\n  origin: [1.0, -2.0, 0.0], occupied_thresh: 0.5}\n");
  EXPECT_EQ(voxel_set(vola::io::read_ros_map((dir / "f.yaml").string(), 0).voxels),
            voxel_set(vola::io::read_ros_map((dir / "b.yaml").string(), 0).voxels));
}

// A map saved as PNG (map_saver --fmt png) reads as its PGM: grey as it is, colour
// channels averaged (alpha is not written here: PngImage writes grey or RGB).
TEST(RosMap, PngMapsReadAsTheirPgm) {
  vola_test::TempDir dir;
  const std::uint8_t grey[6] = {0, 254, 205, 100, 0, 254};
  write_text(dir / "grey.pgm", "P5\n3 2\n255\n" + std::string(reinterpret_cast<const char*>(grey), 6));
  vola::io::write_png((dir / "grey.png").string(), 3, 2, grey, 8, vola::io::PngColour::grey);
  // Colour pixels whose channel means are the grey values above (the last: 252.7, free too).
  const std::uint8_t rgb[18] = {0, 0, 0, 254, 254, 254, 200, 210, 205, 90, 100, 110, 0, 0, 0, 250, 254, 254};
  vola::io::write_png((dir / "rgb.png").string(), 3, 2, rgb, 8, vola::io::PngColour::rgb);
  const auto cells = [&](const std::string& image) {
    write_text(dir / "m.yaml", "image: " + image + "\nresolution: 1\norigin: [0, 0, 0]\noccupied_thresh: 0.5\n");
    return voxel_set(vola::io::read_ros_map((dir / "m.yaml").string(), 0).voxels);
  };
  const auto expected = cells("grey.pgm");
  EXPECT_EQ(expected.size(), 3u);
  EXPECT_EQ(cells("grey.png"), expected);
  EXPECT_EQ(cells("rgb.png"), expected);
}

TEST(RosMap, BadMapsAreFormatErrorsNamingTheFile) {
  vola_test::TempDir dir;
  write_text(dir / "ok.pgm", "P5\n2 2\n255\n" + std::string(4, '\0'));
  const auto error_of = [&](const std::string& name, const std::string& yaml) {
    write_text(dir / name, yaml);
    const std::string path = (dir / name).string();
    try {
      vola::io::read_ros_map(path, 0);
    } catch (const vola::FormatError& e) {
      return std::string(e.what());
    }
    return std::string("read");
  };
  const std::string base = "image: ok.pgm\nresolution: 0.1\n";
  EXPECT_NE(error_of("nested.yaml", base + "origin: [[[[[0]]]], 0, 0]\n").find("nested list"), std::string::npos);
  EXPECT_NE(error_of("map.yaml", base + "origin: {x: 0}\n").find("a mapping under 'origin'"), std::string::npos);
  EXPECT_NE(error_of("indent.yaml", base + "origin: [0, 0, 0]\n  extra: 1\n").find("an indented line"),
            std::string::npos);
  EXPECT_NE(error_of("yaw.yaml", base + "origin: [0, 0, 1.57]\n").find("turned by yaw 1.57"), std::string::npos);
  EXPECT_NE(error_of("noimage.yaml", "resolution: 0.1\norigin: [0, 0, 0]\n").find("no 'image'"), std::string::npos);
  EXPECT_NE(error_of("noorigin.yaml", base).find("no 'origin'"), std::string::npos);
  EXPECT_NE(error_of("twice.yaml", base + base + "origin: [0, 0, 0]\n").find("given twice"), std::string::npos);
  EXPECT_NE(error_of("short.yaml", base + "origin: [0]\n").find("'origin' needs 2 values"), std::string::npos);
  EXPECT_NE(error_of("nan.yaml", "image: ok.pgm\nresolution: nan\norigin: [0, 0, 0]\n").find("not a finite number"),
            std::string::npos);
  EXPECT_NE(error_of("mode.yaml", base + "origin: [0, 0, 0]\nmode: fancy\n").find("mode 'fancy'"), std::string::npos);
  // A PGM whose header claims more than the file holds is refused before anything that
  // size is allocated (2^31 cells here); one that is cut short names its byte.
  write_text(dir / "lying.pgm", "P5\n65536 32768\n255\n" + std::string(16, '\0'));
  EXPECT_NE(error_of("lying.yaml", "image: lying.pgm\nresolution: 1\norigin: [0, 0, 0]\n").find("cells is more than"),
            std::string::npos);
  write_text(dir / "cut.pgm", "P5\n100 100\n255\n" + std::string(16, '\0'));
  EXPECT_NE(error_of("cut.yaml", "image: cut.pgm\nresolution: 1\norigin: [0, 0, 0]\n").find("byte 15: PGM: truncated"),
            std::string::npos)
      << error_of("cut.yaml", "image: cut.pgm\nresolution: 1\norigin: [0, 0, 0]\n");
  EXPECT_NE(error_of("png.yaml", "image: noimage.yaml\nresolution: 1\norigin: [0, 0, 0]\n")
                .find("not a PGM (P5 or P2) or PNG image"),
            std::string::npos);
  // A text sample of seven digits was cut after six and its last digit read as the next
  // sample (a phantom obstacle); samples beyond width x height were ignored.
  write_text(dir / "long.pgm", "P2\n3 1\n255\n2550000 255 255\n");
  EXPECT_NE(error_of("long.yaml", "image: long.pgm\nresolution: 1\norigin: [0, 0, 0]\n")
                .find("byte 11: PGM: sample 0 is above the header's maxval 255"),
            std::string::npos)
      << error_of("long.yaml", "image: long.pgm\nresolution: 1\norigin: [0, 0, 0]\n");
  write_text(dir / "more.pgm", "P2\n2 1\n255\n0 255 254 254 254 254\n");
  EXPECT_NE(error_of("more.yaml", "image: more.pgm\nresolution: 1\norigin: [0, 0, 0]\n")
                .find("PGM: more samples than the header's 2 x 1"),
            std::string::npos);
}

TEST(RosMap, AMapWithNoOccupiedCellIsAnEmptyGrid) {
  // A robot's first map or an empty room: every cell free or unknown. It is read, not
  // refused, so `vola info` describes it (0 occupied cells) as it does an empty binvox.
  vola_test::TempDir dir;
  write_text(dir / "white.pgm", "P5\n3 2\n255\n" + std::string(5, '\xfe') + std::string(1, '\xcd'));
  write_text(dir / "empty.yaml", "image: white.pgm\nresolution: 0.5\norigin: [1, 2, 0]\n");
  const vola::io::VoxelGrid grid = vola::io::read_ros_map((dir / "empty.yaml").string(), 0);
  EXPECT_TRUE(grid.voxels.empty());
  EXPECT_EQ(grid.dims, (std::array<std::uint32_t, 3>{3, 2, 1}));
  EXPECT_EQ(grid.origin, (vola::Point{1, 2, 0}));
  EXPECT_EQ(grid.voxel_size, 0.5);
}
