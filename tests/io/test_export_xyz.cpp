// XYZ export: points -> vol -> XYZ -> the project's text reader -> vol keeps the voxel
// set, on grid trees of every depth and on a reference (toolkit) file; every number
// reads back exactly.
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include "export_test_support.hpp"
#include "vola/builder.hpp"
#include "vola/io/export.hpp"
#include "vola/io/input.hpp"

namespace {

using namespace vola_export_test;
using vola_test::TempDir;

std::vector<std::string> lines_of(const vola_test::fs::path& file) {
  std::ifstream in(file);
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

class XyzRoundTrip : public ::testing::TestWithParam<int> {};

TEST_P(XyzRoundTrip, KeepsVoxelsAndEveryValueExactly) {
  const int depth = GetParam();
  for (std::uint64_t seed = 0; seed < 6; ++seed) {
    const Sample s = random_sample(2000 * depth + seed, depth, true);
    SCOPED_TRACE(s.describe);
    TempDir dir;
    const auto file = dir / "out.xyz";
    vola::io::write_xyz(s.tree, file.string());

    const vola::io::Input in = vola::io::read_input(file.string(), "auto", {});
    EXPECT_EQ(in.format, "text");
    EXPECT_EQ(vola_test::voxel_set(rebuild(in, s.grid)), s.voxels);

    const auto lines = lines_of(file);
    ASSERT_EQ(lines.size(), 1 + s.tree.voxel_count());
    EXPECT_EQ(lines[0], "# x y z red green blue intensity classification number_of_returns reflectance temperature pulse");
    const auto sequence = vola_test::voxel_sequence(s.tree);
    const vola::Quantizer q = s.tree.quantizer();
    const auto& columns = s.tree.attributes().columns();
    for (std::size_t i = 0; i < sequence.size(); ++i) {
      std::istringstream line(lines[i + 1]);
      const vola::Point c = q.center(vola_test::to_voxel(sequence[i]));
      for (int a = 0; a < 3; ++a) {
        std::string token;
        line >> token;
        ASSERT_EQ(std::stod(token), c[a]) << "line " << i + 2;
      }
      for (const auto& column : columns) {
        std::string token;
        line >> token;
        const double value = column.type() == vola::ValueType::f32 ? std::stof(token) : std::stod(token);
        ASSERT_EQ(value, column.get(i)) << column.name() << ", line " << i + 2;
      }
      std::string rest;
      EXPECT_FALSE(line >> rest) << "extra column on line " << i + 2;
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Depths, XyzRoundTrip, ::testing::Range(1, 7));

TEST(XyzExport, ToolkitFileRoundTripsThroughToolkitQuantization) {
  VOLA_REQUIRE_GOLDEN(golden);
  const auto vol = golden / "crs29902_sparse" / "crs29902_sparse.vol";
  const vola::Tree tree = vola::read(vol.string());
  ASSERT_FALSE(tree.stored_frame().has_value());  // a reference file: the grid comes from the header bbox
  TempDir dir;
  const auto file = dir / "out.xyz";
  vola::io::write_xyz(tree, file.string());
  const vola::io::Input in = vola::io::read_input(file.string(), "auto", {});
  vola::BuildOptions options;
  options.quantization = vola::Quantization::toolkit;
  options.depth = tree.depth();
  options.bbox = tree.georef().bbox;
  EXPECT_EQ(vola_test::voxel_set(vola::build(in.cloud, options)), vola_test::voxel_set(tree));
  EXPECT_EQ(vola_test::voxel_set(tree), vola_test::read_voxel_list(golden / "crs29902_sparse" / "expected_voxels.txt"));
}

// Names the text reader splits at (a PDAL CSV's "a,b" or "x;y", quotes) become '_': the
// export reads back with one column per value (it was one more name than values).
TEST(XyzExport, NamesWithSeparatorsReadBackAsOneColumnEach) {
  vola::Tree tree = vola::build_from_voxels(std::vector<vola::Voxel>{{0, 0, 0}, {1, 2, 3}}, 2);
  for (const char* name : {"M3C2 distance", "a,b", "c;d", "\"q\""}) {
    vola::AttributeColumn column(name, vola::ValueType::f64, vola::Reduction::mean, 2);
    column.set(0, 1.5);
    column.set(1, -2.0);
    tree.attributes().add(std::move(column));
  }
  TempDir dir;
  vola::io::write_xyz(tree, (dir / "s.xyz").string());
  EXPECT_EQ(lines_of(dir / "s.xyz")[0], "# x y z M3C2_distance a_b c_d _q_");
  const vola::io::Input in = vola::io::read_input((dir / "s.xyz").string(), "auto", {});
  ASSERT_EQ(in.cloud.attributes.size(), 4u);
  for (const auto& a : in.cloud.attributes) EXPECT_EQ(a.values, (std::vector<double>{1.5, -2.0})) << a.name;
}

// CSV: PDAL's writers.text header, the LAS columns in PDAL's spelling; read back by the
// text reader into the same columns and values.
TEST(XyzExport, CsvCarriesPdalsHeaderAndReadsBack) {
  const Sample s = random_sample(77, 3, true);
  TempDir dir;
  vola::io::write_csv(s.tree, (dir / "out.csv").string());
  const auto lines = lines_of(dir / "out.csv");
  ASSERT_EQ(lines.size(), 1 + s.tree.voxel_count());
  EXPECT_EQ(lines[0],
            "\"X\",\"Y\",\"Z\",\"Red\",\"Green\",\"Blue\",\"Intensity\",\"Classification\",\"NumberOfReturns\","
            "\"reflectance\",\"temperature\",\"pulse\"");
  const vola::io::Input in = vola::io::read_input((dir / "out.csv").string(), "auto", {});
  EXPECT_EQ(vola_test::voxel_set(rebuild(in, s.grid)), s.voxels);
  const auto& columns = s.tree.attributes().columns();
  ASSERT_EQ(in.cloud.attributes.size(), columns.size());
  for (std::size_t c = 0; c < columns.size(); ++c) {
    EXPECT_EQ(in.cloud.attributes[c].name, columns[c].name());
    for (std::size_t i = 0; i < columns[c].size(); ++i) {
      const double read = in.cloud.attributes[c].values[i], written = columns[c].get(i);
      if (columns[c].type() == vola::ValueType::f32)  // written as the shortest text of the float
        ASSERT_EQ(static_cast<float>(read), static_cast<float>(written)) << columns[c].name() << " " << i;
      else
        ASSERT_EQ(read, written) << columns[c].name() << " " << i;
    }
  }
}

// Two names PDAL's spelling makes one (intensity and Intensity; x): each stays its own
// column in the CSV header (the reader kept one of the two Intensity columns).
TEST(XyzExport, CsvNamesStayDistinctOnceSpelledAsPdalSpellsThem) {
  vola::Tree tree = vola::build_from_voxels(std::vector<vola::Voxel>{{0, 0, 0}}, 1);
  for (const char* name : {"intensity", "Intensity", "X"}) {
    vola::AttributeColumn column(name, vola::ValueType::f64, vola::Reduction::mean, 1);
    column.set(0, 3.0);
    tree.attributes().add(std::move(column));
  }
  TempDir dir;
  vola::io::write_csv(tree, (dir / "d.csv").string());
  EXPECT_EQ(lines_of(dir / "d.csv")[0], "\"X\",\"Y\",\"Z\",\"Intensity\",\"Intensity_2\",\"X_2\"");
  EXPECT_EQ(vola::io::read_input((dir / "d.csv").string(), "auto", {}).cloud.attributes.size(), 3u);
}

TEST(XyzExport, EmptyTreeHasOnlyTheHeader) {
  TempDir dir;
  vola::io::write_xyz(vola::Tree(), (dir / "e.xyz").string());
  EXPECT_EQ(lines_of(dir / "e.xyz"), std::vector<std::string>{"# x y z"});
}

TEST(XyzExport, UnwritablePathIsAnIoErrorAndLeavesNothing) {
  TempDir dir;
  const auto file = dir / "missing_dir" / "out.xyz";
  EXPECT_THROW(vola::io::write_xyz(random_sample(1, 2, false).tree, file.string()), vola::IoError);
  EXPECT_FALSE(vola_test::fs::exists(file));
}

}  // namespace
