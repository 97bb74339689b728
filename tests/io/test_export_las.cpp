// LAS export: points -> vol -> LAS -> the project's LAS reader -> vol keeps the voxel
// set and the attributes, on random trees of every depth and on a real survey; the
// header says what the specification asks (1.4, format 6/7, scale, offset, bounds, WKT).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "export_test_support.hpp"
#include "vola/geo/crs.hpp"
#include "vola/io/export.hpp"
#include "vola/io/input.hpp"
#include "vola/io/las.hpp"

namespace {

using namespace vola_export_test;
using vola_test::TempDir;

// The LAS reader's columns for the export's: every column comes back by name, "height"
// too (written as extra bytes: a voxel's mean z is not its centre's z). Without a height
// column, the reader's height is the z of the one point per voxel, the centre.
void expect_same_attributes(const vola::Tree& original, const vola::Tree& again) {
  const vola::Quantizer q = original.quantizer();
  const bool has_height = original.attributes().find("height") != nullptr;
  original.for_each_voxel([&](const vola::Voxel& v) {
    const auto r0 = original.rank(v), r1 = again.rank(v);
    ASSERT_TRUE(r0 && r1);
    for (const auto& column : original.attributes().columns()) {
      const vola::AttributeColumn* back = again.attributes().find(column.name());
      ASSERT_NE(back, nullptr) << column.name() << " did not come back";
      ASSERT_EQ(back->get(*r1), column.get(*r0)) << column.name();
    }
    if (has_height) return;
    const vola::AttributeColumn* height = again.attributes().find("height");
    ASSERT_NE(height, nullptr);
    const double z = q.center(v)[2];
    ASSERT_NEAR(height->get(*r1), z, 1e-6 * std::abs(z) + 1e-3 * original.frame().voxel_size);
  });
}

class LasRoundTrip : public ::testing::TestWithParam<int> {};

TEST_P(LasRoundTrip, KeepsVoxelsAndAttributes) {
  const int depth = GetParam();
  for (std::uint64_t seed = 0; seed < 6; ++seed) {
    const Sample s = random_sample(3000 * depth + seed, depth, true);
    SCOPED_TRACE(s.describe);
    TempDir dir;
    const auto file = dir / "out.las";
    const vola::io::LasReport report = vola::io::write_las(s.tree, file.string());
    EXPECT_EQ(report.point_format, 7);
    EXPECT_EQ(report.extra_bytes, (std::vector<std::string>{"reflectance", "temperature", "pulse"}));
    EXPECT_FALSE(report.has_crs);

    const vola::io::Input in = vola::io::read_input(file.string(), "auto", {});
    EXPECT_EQ(in.format, "las");
    const vola::Tree again = rebuild(in, s.grid);
    EXPECT_EQ(vola_test::voxel_set(again), s.voxels);
    expect_same_attributes(s.tree, again);
  }
}

INSTANTIATE_TEST_SUITE_P(Depths, LasRoundTrip, ::testing::Range(1, 7));

TEST(LasExport, HeaderFollowsTheSpecification) {
  for (bool attributes : {true, false}) {
    const Sample s = random_sample(41, 4, attributes);
    TempDir dir;
    const auto file = dir / "out.las";
    vola::io::write_las(s.tree, file.string());
    vola::io::LasReader reader(file.string());
    const vola::io::LasHeader& h = reader.header();
    EXPECT_EQ(h.version(), "1.4");
    EXPECT_EQ(h.header_size, 375);
    EXPECT_EQ(h.point_format, attributes ? 7 : 6);
    EXPECT_EQ(h.record_length, attributes ? 36 + 4 + 2 + 4 : 30);
    EXPECT_EQ(h.point_count, s.tree.voxel_count());
    EXPECT_EQ(h.global_encoding & 16, 16);  // the WKT bit, which formats 6-10 require, CRS or none
    const auto bytes = vola_test::read_bytes(file);
    EXPECT_EQ(vola_test::get_le<std::uint32_t>(bytes, 107), 0u);  // legacy count: 0 for formats 6-10
    EXPECT_EQ(vola_test::get_le<std::uint64_t>(bytes, 255), s.tree.voxel_count());  // all first returns
    for (std::size_t k = 1; k < 15; ++k) EXPECT_EQ(vola_test::get_le<std::uint64_t>(bytes, 255 + 8 * k), 0u) << k + 1;
    const double vs = s.grid.voxel_size;
    vola::Point low{1e300, 1e300, 1e300}, high{-1e300, -1e300, -1e300};
    const vola::Quantizer q = s.tree.quantizer();
    s.tree.for_each_voxel([&](const vola::Voxel& v) {
      const vola::Point c = q.center(v);
      for (int a = 0; a < 3; ++a) {
        low[a] = std::min(low[a], c[a]);
        high[a] = std::max(high[a], c[a]);
      }
    });
    for (int a = 0; a < 3; ++a) {
      EXPECT_LE(h.scale[a], vs / 1000);
      EXPECT_GT(h.scale[a], vs / 10000);
      EXPECT_EQ(std::log10(h.scale[a]), std::round(std::log10(h.scale[a])));  // a power of ten
      EXPECT_EQ(h.offset[a], s.grid.origin[a]);
      EXPECT_NEAR(h.min[a], low[a], h.scale[a]);
      EXPECT_NEAR(h.max[a], high[a], h.scale[a]);
    }
    // Points are the centres, to half the scale.
    vola::io::LasChunk chunk;
    reader.read(chunk, h.point_count);
    const auto sequence = vola_test::voxel_sequence(s.tree);
    ASSERT_EQ(chunk.size(), sequence.size());
    for (std::size_t i = 0; i < sequence.size(); ++i) {
      const vola::Point c = q.center(vola_test::to_voxel(sequence[i]));
      for (int a = 0; a < 3; ++a) ASSERT_NEAR(chunk.xyz[3 * i + a], c[a], h.scale[a] * 0.5000001 + 1e-9 * std::abs(c[a]));
      ASSERT_EQ(chunk.return_number[i], 1);
    }
  }
}

TEST(LasExport, DeepestGridStillFitsThirtyTwoBitCoordinates) {
  // Depth 10: 4^10 voxels per axis, so 1/1000 of a voxel would overflow; the scale grows.
  const std::vector<vola::Voxel> corners{{0, 0, 0}, {1048575, 1048575, 1048575}, {1048575, 0, 524288}};
  Grid grid;
  grid.depth = 10;
  grid.voxel_size = 0.05;
  grid.origin = {315000.25, 234000.5, -12.75};
  vola_test::XyzSet voxels;
  for (const auto& v : corners) voxels.insert(vola_test::to_xyz(v));
  const vola::Tree tree = build_on(points_in_voxels(voxels, grid, 1, false), grid);
  TempDir dir;
  const auto file = dir / "deep.las";
  const auto report = vola::io::write_las(tree, file.string());
  EXPECT_LE(report.scale, grid.voxel_size / 100);
  EXPECT_EQ(vola_test::voxel_set(rebuild(vola::io::read_input(file.string(), "auto", {}), grid)), voxels);
}

vola::Tree tree_with_crs(std::uint32_t epsg, const std::string& wkt) {
  Sample s = random_sample(5, 3, false);
  s.tree.georef().epsg = epsg;
  s.tree.georef().crs_wkt = wkt;
  return s.tree;
}

std::optional<std::uint32_t> written_epsg(const vola::Tree& tree, bool& has_crs, std::string& wkt) {
  TempDir dir;
  const auto file = dir / "crs.las";
  has_crs = vola::io::write_las(tree, file.string()).has_crs;
  vola::io::LasReader reader(file.string());
  wkt = reader.header().wkt;
  EXPECT_NE(reader.header().global_encoding & 16, 0) << "WKT bit";
  if (wkt.empty()) return std::nullopt;
  return vola::geo::epsg_from_wkt(wkt);
}

TEST(LasExport, CrsAsWkt) {
  bool has_crs = false;
  std::string wkt;
  // Only an EPSG code: PROJ's WKT1 for it.
  EXPECT_EQ(written_epsg(tree_with_crs(29902, ""), has_crs, wkt), 29902u);
  EXPECT_TRUE(has_crs);
  EXPECT_EQ(wkt.rfind("PROJCS[", 0), 0u) << wkt.substr(0, 40);  // WKT1, as LAS readers expect
  // WKT2 in the tree: written as WKT1 of the same CRS.
  EXPECT_EQ(written_epsg(tree_with_crs(2000, vola::geo::crs_wkt(26910)), has_crs, wkt), 26910u);
  EXPECT_EQ(wkt.rfind("PROJCS[", 0), 0u);
  // No CRS at all: none invented.
  EXPECT_EQ(written_epsg(tree_with_crs(vola::geo::kUnsetEpsg, ""), has_crs, wkt), std::nullopt);
  EXPECT_FALSE(has_crs);
  EXPECT_TRUE(wkt.empty());
  // A code PROJ does not know: no record rather than a wrong one.
  EXPECT_EQ(written_epsg(tree_with_crs(999999, ""), has_crs, wkt), std::nullopt);
  EXPECT_FALSE(has_crs);
}

TEST(LasExport, EightBitColoursWidenAndReturnsClamp) {
  vola::Tree tree = vola::build_from_voxels(std::vector<vola::Voxel>{{0, 0, 0}, {1, 0, 0}, {2, 0, 0}}, 1);
  tree.set_frame({vola::Quantization::grid, {0, 0, 0}, 1.0});
  const double values[3] = {0, 128, 255};
  for (const char* name : {"red", "green", "blue"}) {
    vola::AttributeColumn c(name, vola::ValueType::u8, vola::Reduction::mean, 3);
    for (int i = 0; i < 3; ++i) c.set(static_cast<std::size_t>(i), values[i]);
    tree.attributes().add(std::move(c));
  }
  vola::AttributeColumn returns("number_of_returns", vola::ValueType::f32, vola::Reduction::max, 3);
  returns.set(0, 0);
  returns.set(1, 2.4f);
  returns.set(2, 40);  // 4 bits in formats 6-10
  tree.attributes().add(std::move(returns));
  TempDir dir;
  const auto file = dir / "c.las";
  vola::io::write_las(tree, file.string());
  vola::io::LasReader reader(file.string());
  vola::io::LasChunk chunk;
  ASSERT_EQ(reader.read(chunk, 10), 3u);
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(chunk.red[i], values[i] * 257);
    EXPECT_EQ(chunk.blue[i], values[i] * 257);
  }
  EXPECT_EQ(chunk.number_of_returns[0], 0);
  EXPECT_EQ(chunk.return_number[0], 0);
  EXPECT_EQ(chunk.number_of_returns[1], 2);
  EXPECT_EQ(chunk.return_number[1], 1);
  EXPECT_EQ(chunk.number_of_returns[2], 15);
  EXPECT_EQ(vola_test::get_le<std::uint64_t>(vola_test::read_bytes(file), 255), 2u);  // first returns
}

TEST(LasExport, ExtraBytesNamesFitThirtyTwoBytesAndStayUnique) {
  vola::Tree tree = vola::build_from_voxels(std::vector<vola::Voxel>{{1, 2, 3}}, 1);
  tree.set_frame({vola::Quantization::grid, {0, 0, 0}, 1.0});
  const std::string long_name(40, 'a');
  vola::AttributeColumn a(long_name, vola::ValueType::i64, vola::Reduction::last, 1);
  a.set(0, -123456789);
  tree.attributes().add(std::move(a));
  vola::AttributeColumn b(long_name + "b", vola::ValueType::f64, vola::Reduction::mean, 1);
  b.set(0, 0.1);
  tree.attributes().add(std::move(b));
  TempDir dir;
  const auto file = dir / "e.las";
  const auto report = vola::io::write_las(tree, file.string());
  ASSERT_EQ(report.extra_bytes.size(), 2u);
  EXPECT_EQ(report.extra_bytes[0], std::string(32, 'a'));
  EXPECT_EQ(report.extra_bytes[1], std::string(30, 'a') + "_2");
  vola::io::LasReader reader(file.string());
  ASSERT_EQ(reader.header().extra_fields.size(), 2u);
  vola::io::LasChunk chunk;
  reader.read(chunk, 1);
  EXPECT_EQ(chunk.extra[0][0], -123456789);
  EXPECT_EQ(chunk.extra[1][0], 0.1);
}

TEST(LasExport, AutzenSurveyRoundTrips) {
  const auto las = data_dir() / "las" / "pdal_autzen-utm.las";
  VOLA_REQUIRE_DATA_FILE(las);
  const vola::io::Input survey = vola::io::read_input(las.string(), "auto", {});
  Grid grid;
  grid.origin = {493990, 4877420, 120};
  grid.voxel_size = 2.0;
  grid.depth = 5;
  vola::Tree tree = build_on(survey.cloud, grid);
  tree.georef().epsg = survey.epsg.value_or(vola::geo::kUnsetEpsg);
  ASSERT_EQ(tree.georef().epsg, 26910u);
  ASSERT_GT(tree.voxel_count(), 1000u);

  TempDir dir;
  const auto file = dir / "autzen.las";
  const auto report = vola::io::write_las(tree, file.string());
  EXPECT_EQ(report.point_format, 7);
  EXPECT_TRUE(report.has_crs);
  EXPECT_EQ(report.extra_bytes, std::vector<std::string>{"height"});  // the survey's mean z per voxel
  const vola::io::Input in = vola::io::read_input(file.string(), "auto", {});
  ASSERT_FALSE(in.wkt.empty());
  EXPECT_EQ(vola::geo::epsg_from_wkt(in.wkt), 26910u);
  const vola::Tree again = rebuild(in, grid);
  EXPECT_EQ(vola_test::voxel_set(again), vola_test::voxel_set(tree));
  expect_same_attributes(tree, again);
}

// LAS intensity is 16-bit: wider values are written as 65535 and the report counts them
// (the CLI warns), instead of a silent clamp.
TEST(LasExport, IntensitiesAboveSixteenBitsAreCounted) {
  vola::Tree tree = vola::build_from_voxels(std::vector<vola::Voxel>{{0, 0, 0}, {1, 1, 1}, {2, 2, 2}}, 1);
  vola::AttributeColumn intensity("intensity", vola::ValueType::u32, vola::Reduction::mean, 3);
  intensity.set(0, 70000);
  intensity.set(1, 65535);
  intensity.set(2, 1e9);
  tree.attributes().add(std::move(intensity));
  TempDir dir;
  const auto report = vola::io::write_las(tree, (dir / "wide.las").string());
  EXPECT_EQ(report.clamped_intensities, 2u);
  EXPECT_EQ(report.unfit_values,
            std::vector<std::string>{"intensity: 2 values outside LAS's 0..65535 were clamped to it"});
}

// Every standard field fed from a column wider than it says what it changed: a
// classification of 300 became 255, a NaN intensity 0, without a word.
TEST(LasExport, ValuesAStandardFieldCannotHoldAreSaid) {
  vola::Tree tree = vola::build_from_voxels(std::vector<vola::Voxel>{{0, 0, 0}, {1, 1, 1}, {2, 2, 2}}, 1);
  vola::AttributeColumn classification("classification", vola::ValueType::i32, vola::Reduction::majority, 3);
  classification.set(0, 300);
  classification.set(1, -1);
  classification.set(2, 6);
  vola::AttributeColumn intensity("intensity", vola::ValueType::f32, vola::Reduction::mean, 3);
  intensity.set(0, std::nan(""));
  intensity.set(1, 12.5);
  intensity.set(2, 40);
  vola::AttributeColumn user_data("user_data", vola::ValueType::u8, vola::Reduction::last, 3);  // fits: not watched
  tree.attributes().add(std::move(classification));
  tree.attributes().add(std::move(intensity));
  tree.attributes().add(std::move(user_data));
  TempDir dir;
  const auto report = vola::io::write_las(tree, (dir / "unfit.las").string());
  EXPECT_EQ(report.clamped_intensities, 0u);
  EXPECT_EQ(report.unfit_values,
            (std::vector<std::string>{"intensity: 1 values that are not numbers were written as 0",
                                      "classification: 2 values outside LAS's 0..255 were clamped to it"}));
  vola::io::LasReader reader((dir / "unfit.las").string());
  vola::io::LasChunk points;
  ASSERT_EQ(reader.read(points, 10), 3u);
  EXPECT_EQ(points.classification, (std::vector<std::uint8_t>{255, 0, 6}));
  EXPECT_EQ(points.intensity, (std::vector<std::uint16_t>{0, 12, 40}));
}

TEST(LasExport, EmptyTree) {
  TempDir dir;
  const auto file = dir / "empty.las";
  vola::io::write_las(vola::Tree(), file.string());
  vola::io::LasReader reader(file.string());
  EXPECT_EQ(reader.header().point_count, 0u);
}

}  // namespace
