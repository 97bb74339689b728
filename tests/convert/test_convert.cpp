// The conversion pipeline's library face: options checked once with errors that name the
// options member, the CRS rules, and conversions of real files against the plain builder.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <numbers>
#include <regex>
#include <string>
#include <vector>

#include "../io/e57_test_file.hpp"
#include "../io/io_test_data.hpp"
#include "vola/builder.hpp"
#include "vola/convert.hpp"
#include "vola/crs_rules.hpp"
#include "vola/error.hpp"
#include "vola/file.hpp"
#include "vola/geo/crs.hpp"
#include "vola/io/las.hpp"

namespace {

// The member an OptionError names, or "" when `f` throws no OptionError.
template <class F>
std::string refused_option(F&& f) {
  try {
    f();
  } catch (const vola::OptionError& e) {
    return e.option();
  }
  return "";
}

TEST(ConvertOptions, ErrorsNameTheMemberThatIsWrong) {
  vola::ConvertOptions o;
  o.quantization = vola::Quantization::toolkit;
  o.depth = 4;
  EXPECT_EQ(refused_option([&] { o.check(); }), "");
  o.voxel_size = 1.0;
  EXPECT_EQ(refused_option([&] { o.check(); }), "voxel_size");
  o.voxel_size = 0.0;
  o.depth = 11;
  EXPECT_EQ(refused_option([&] { o.check(); }), "depth");
  o.depth = 4;
  o.nbits = 65;
  EXPECT_EQ(refused_option([&] { o.check(); }), "nbits");
  o.nbits = 0;
  o.text_attributes = {"intensity=x"};
  EXPECT_EQ(refused_option([&] { o.check(); }), "text_attributes");
  o.text_attributes = {"intensity=4:u16:median"};
  EXPECT_EQ(refused_option([&] { o.check(); }), "text_attributes");
  o.text_attributes = {"intensity=4:u16:max"};
  o.bbox = vola::Box{{1, 1, 1}, {0, 0, 0}};
  EXPECT_EQ(refused_option([&] { o.check(); }), "bbox");
  o.bbox.reset();
  o.dense = o.compress = true;
  EXPECT_EQ(refused_option([&] { o.check(); }), "compress");
}

// --attribute NAME=COL without a reduction reduces as a header's column of that name
// would: a tree id by majority, a measurement by mean.
TEST(ConvertOptions, TextAttributesWithoutAReductionGoByTheirName) {
  const vola_test::TempDir dir;
  const auto path = dir.path() / "trees.xyz";
  std::ofstream(path) << "0.1 0.1 0.1 3 1\n0.2 0.2 0.2 5 2\n0.3 0.3 0.3 5 6\n";
  vola::ConvertOptions o;
  o.voxel_size = 1.0;
  o.text_attributes = {"treeID=4", "temperature=5", "cls=4:u8:mean"};
  const vola::Tree tree = vola::convert(path.string(), o);
  ASSERT_NE(tree.attributes().find("treeID"), nullptr);
  EXPECT_EQ(tree.attributes().find("treeID")->reduction(), vola::Reduction::majority);
  EXPECT_EQ(tree.attributes().find("treeID")->get(0), 5.0);
  EXPECT_EQ(tree.attributes().find("temperature")->reduction(), vola::Reduction::mean);
  EXPECT_EQ(tree.attributes().find("temperature")->get(0), 3.0);
  EXPECT_EQ(tree.attributes().find("cls")->reduction(), vola::Reduction::mean);  // given, so kept
}

TEST(BuildOptions, CheckOwnsTheQuantizationRules) {
  vola::BuildOptions b;
  b.quantization = vola::Quantization::grid;
  EXPECT_EQ(refused_option([&] { b.check(); }), "voxel_size");  // neither a size nor a depth
  b.voxel_size = 0.5;
  EXPECT_EQ(refused_option([&] { b.check(); }), "");
  b.voxel_size = std::numeric_limits<double>::infinity();
  EXPECT_EQ(refused_option([&] { b.check(); }), "voxel_size");
  b.quantization = vola::Quantization::toolkit;
  b.voxel_size = 0.0;
  EXPECT_EQ(refused_option([&] { b.check(); }), "depth");
  b.depth = 3;
  b.origin = vola::Point{0, 0, 0};
  EXPECT_EQ(refused_option([&] { b.check(); }), "origin");
}

TEST(ResolveQuantizer, LeavesItsOptionsAlone) {
  vola::BuildOptions b;
  b.quantization = vola::Quantization::grid;
  b.voxel_size = 2.0;
  const vola::BuildOptions before = b;
  const vola::Quantizer q = vola::resolve_quantizer(vola::Box{{1, 1, 1}, {100, 50, 20}}, b);
  EXPECT_EQ(b.depth, before.depth);
  EXPECT_FALSE(b.origin.has_value());
  EXPECT_EQ(q.frame().voxel_size, 2.0);
  EXPECT_EQ(q.frame().origin, (vola::Point{0, 0, 0}));  // the bbox min snapped to the voxel size
  EXPECT_EQ(q.depth(), 3);                               // 64 voxels of 2 cover 100
}

TEST(ResolveCrs, TheGivenCodeWinsAndInputsMustAgree) {
  const std::vector<vola::StatedCrs> agree{{"a.las", 32610, ""}, {"b.las", 32610, ""}};
  const vola::ResolvedCrs crs = vola::resolve_crs(agree);
  EXPECT_EQ(crs.epsg, 32610u);
  EXPECT_NE(crs.wkt.find("32610"), std::string::npos);
  EXPECT_FALSE(crs.given);

  const std::vector<vola::StatedCrs> nothing{{"a.xyz", std::nullopt, ""}, {"b.xyz", std::nullopt, ""}};
  const vola::ResolvedCrs none = vola::resolve_crs(nothing);
  EXPECT_FALSE(none.epsg.has_value());
  EXPECT_TRUE(none.wkt.empty());
  EXPECT_FALSE(none.stated);

  const std::vector<vola::StatedCrs> differ{{"a.las", 32610, ""}, {"b.las", std::nullopt, ""}};
  try {
    vola::resolve_crs(differ);
    FAIL() << "inputs with and without a CRS were accepted";
  } catch (const vola::InvalidArgument& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("a.las says EPSG:32610"), std::string::npos) << what;
    EXPECT_NE(what.find("b.las says nothing"), std::string::npos) << what;
  }
  const vola::ResolvedCrs given = vola::resolve_crs(differ, "4326");
  EXPECT_EQ(given.epsg, 4326u);
  EXPECT_TRUE(given.given);
  EXPECT_TRUE(given.stated);
  EXPECT_THROW(vola::resolve_crs({}, "999999"), vola::Error);
}

// What a LAS file says its CRS is, as convert and tile state it.
vola::StatedCrs stated_crs_of(const std::filesystem::path& las) {
  const vola::io::LasReader reader(las.string());
  return {las.filename().string(), reader.header().epsg, reader.header().wkt};
}

// Two writers' spellings of the Autzen survey's CRS (PDAL's ESRI-style WKT with no code,
// and EPSG:2994 in GeoKeys): the same CRS by meaning; a metre CRS of the same place is not.
TEST(ResolveCrs, InputsAgreeByMeaningNotBySpelling) {
  VOLA_REQUIRE_DATA(data);
  const auto trim = stated_crs_of(data / "las" / "pdal_autzen_trim.las");
  const auto pf1 = stated_crs_of(data / "las" / "pdal_autzen_pf1.las");
  const auto bmx = stated_crs_of(data / "las" / "pdal_autzen-bmx-2010.las");
  ASSERT_FALSE(trim.epsg.has_value());  // a WKT with no code: only PROJ can say what it is
  ASSERT_EQ(pf1.epsg, 2994u);
  EXPECT_NE(trim.wkt, vola::geo::crs_wkt(2994));
  const std::vector<vola::StatedCrs> same{trim, pf1};
  EXPECT_NO_THROW(vola::resolve_crs(same));

  const std::vector<vola::StatedCrs> differ{trim, bmx};
  try {
    vola::resolve_crs(differ);
    FAIL() << "a foot CRS and a metre CRS were taken as one";
  } catch (const vola::InvalidArgument& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("pdal_autzen_trim.las says \"NAD_1983_HARN_Lambert_Conformal_Conic\""), std::string::npos)
        << what;
    EXPECT_NE(what.find("pdal_autzen-bmx-2010.las says EPSG:2991"), std::string::npos) << what;
  }

  // The same WKT respelled as another tool writes it: names with underscores.
  std::string respelled = bmx.wkt;
  for (const auto& [from, to] : std::vector<std::pair<std::string, std::string>>{
           {"GRS 1980", "GRS_1980"}, {"North_American_Datum_1983", "North American Datum 1983"}}) {
    const auto at = respelled.find(from);
    ASSERT_NE(at, std::string::npos) << from;
    respelled.replace(at, from.size(), to);
  }
  const std::vector<vola::StatedCrs> spelled{bmx, {"respelled.las", std::nullopt, respelled}};
  EXPECT_NO_THROW(vola::resolve_crs(spelled));
}

// vola info's naming of a CRS: PROJ's name, a code only when PROJ identifies one, the units.
TEST(DescribeCrs, NamesWhatProjFindsAndInventsNoCode) {
  VOLA_REQUIRE_DATA(data);
  const auto trim = vola::geo::describe_crs(stated_crs_of(data / "las" / "pdal_autzen_trim.las").wkt);
  EXPECT_EQ(trim.name, "NAD_1983_HARN_Lambert_Conformal_Conic");
  EXPECT_FALSE(trim.epsg.has_value());
  EXPECT_EQ(trim.horizontal_unit, "foot");
  EXPECT_NE(vola::geo::crs_summary(trim).find("(no EPSG code)"), std::string::npos);

  const auto bmx = vola::geo::describe_crs(stated_crs_of(data / "las" / "pdal_autzen-bmx-2010.las").wkt);
  EXPECT_EQ(bmx.kind, "compound");
  EXPECT_EQ(bmx.epsg, 2991u);
  EXPECT_EQ(bmx.horizontal_unit, "metre");
  EXPECT_EQ(bmx.vertical_unit, "US survey foot");

  const auto utm = vola::geo::describe_crs("EPSG:32610");
  EXPECT_EQ(utm.name, "WGS 84 / UTM zone 10N");
  EXPECT_EQ(utm.epsg, 32610u);
  EXPECT_TRUE(vola::geo::same_crs("EPSG:4326", "EPSG:4326"));
  EXPECT_FALSE(vola::geo::same_crs("EPSG:32610", "EPSG:32611"));
  EXPECT_THROW(vola::geo::describe_crs("not a crs"), vola::Error);
}

// Without the database search, a description keeps the name, kind and units, and only the
// CRS's own EPSG id: a WKT stripped of its ids is identified by the search alone.
TEST(DescribeCrs, OwnIdOnlySkipsTheSearchAndKeepsKindAndUnits) {
  VOLA_REQUIRE_DATA(data);
  const auto own = vola::geo::EpsgLookup::own_id_only;
  for (const std::string& definition :
       {stated_crs_of(data / "las" / "pdal_autzen_trim.las").wkt, stated_crs_of(data / "las" / "pdal_autzen-bmx-2010.las").wkt,
        std::string("EPSG:32610"), std::string("EPSG:4326")}) {
    const auto searched = vola::geo::describe_crs(definition), quick = vola::geo::describe_crs(definition, own);
    EXPECT_EQ(quick.name, searched.name);
    EXPECT_EQ(quick.kind, searched.kind);
    EXPECT_EQ(quick.horizontal_unit, searched.horizontal_unit);
    EXPECT_EQ(quick.vertical_unit, searched.vertical_unit);
  }
  EXPECT_EQ(vola::geo::describe_crs("EPSG:32610", own).epsg, 32610u);
  const std::string without_ids =
      std::regex_replace(vola::geo::crs_wkt1("EPSG:32610"), std::regex(R"(,AUTHORITY\["EPSG","[0-9]+"\])"), "");
  ASSERT_EQ(without_ids.find("AUTHORITY"), std::string::npos) << without_ids;
  EXPECT_EQ(vola::geo::describe_crs(without_ids).epsg, 32610u);
  EXPECT_FALSE(vola::geo::describe_crs(without_ids, own).epsg.has_value());
}

// What GDAL's PROJ contexts would open: +init files and grids other than @null, in a PROJ
// string or embedded in a WKT.
TEST(CrsFileReference, FindsInitFilesAndGridsButNotTheNullGrid) {
  using vola::geo::crs_file_reference;
  EXPECT_EQ(crs_file_reference("+init=/etc/x:site +type=crs"), "+init=/etc/x:site");
  EXPECT_EQ(crs_file_reference(R"(PROJCS["x",EXTENSION["PROJ4","+proj=utm +INIT = epsg:32633"]])"), "+INIT = epsg:32633");
  EXPECT_EQ(crs_file_reference(R"(REMARK["PROJ CRS string: +proj=longlat +nadgrids=@null,./a.gsb"])"),
            "+nadgrids=@null,./a.gsb");
  EXPECT_EQ(crs_file_reference("+proj=vgridshift +grids=egm96_15.gtx"), "+grids=egm96_15.gtx");
  EXPECT_EQ(crs_file_reference("+proj=tinshift +file=/tmp/t.json"), "+file=/tmp/t.json");
  EXPECT_EQ(crs_file_reference("+proj=merc +a=6378137 +b=6378137 +nadgrids=@null +wktext"), "");
  EXPECT_EQ(crs_file_reference("+proj=utm +zone=33 +datum=WGS84 +units=m +no_defs"), "");
  EXPECT_EQ(crs_file_reference(vola::geo::crs_wkt(32633)), "");
  EXPECT_EQ(crs_file_reference("+init"), "");
  EXPECT_EQ(crs_file_reference("+" + std::string(100000, 'a')), "");
}

// A CRS read from a file (a LAS WKT record, a tile index) may not make PROJ read other
// local files: "+init=FILE:id" is refused, not read. (Grid files named by path, as in
// "+nadgrids=FILE", are not opened either; PROJ treats a grid it cannot open as absent.)
TEST(DescribeCrs, DefinitionsCannotReadOtherLocalFiles) {
  vola_test::TempDir dir;
  const std::string init = (dir / "init").string();
  const std::string line = "<site> +proj=utm +zone=33 +datum=WGS84 +units=m +no_defs <>\n";
  vola_test::write_bytes(dir / "init", std::vector<std::uint8_t>(line.begin(), line.end()));
  EXPECT_THROW(vola::geo::describe_crs("+init=" + init + ":site +type=crs"), vola::Error);
  EXPECT_THROW(vola::geo::crs_wkt1("+init=" + init + ":site"), vola::Error);
  // PROJ's own definitions and grids are still found.
  EXPECT_EQ(vola::geo::describe_crs("+proj=utm +zone=33 +datum=WGS84 +units=m +no_defs +type=crs").kind, "projected");
  EXPECT_EQ(vola::geo::epsg_from_wkt(vola::geo::crs_wkt(32633)), 32633u);
}

// Columns given win over a header's names, 1 2 3 too (taken for the default, they were
// ignored: x came from the header's "x", column 2, without a word).
TEST(Convert, ColumnsGivenWinOverAHeaderEvenOneTwoThree) {
  vola_test::TempDir dir;
  const std::string text = "y x z intensity\n1 2 3 10\n4 5 6 20\n";
  vola_test::write_bytes(dir / "yx.xyz", std::vector<std::uint8_t>(text.begin(), text.end()));
  const std::string path = (dir / "yx.xyz").string();
  vola::ConvertOptions by_name;
  by_name.voxel_size = 1.0;
  EXPECT_EQ(vola::convert(path, by_name).georef().bbox.min, (vola::Point{2, 1, 3}));  // x is the header's column 2
  vola::ConvertOptions given = by_name;
  given.columns = std::array<int, 3>{1, 2, 3};
  const vola::Tree placed = vola::convert(path, given);
  EXPECT_EQ(placed.georef().bbox.min, (vola::Point{1, 2, 3}));
  // The header's other columns are still kept (given columns dropped them all).
  const vola::AttributeColumn* intensity = placed.attributes().find("intensity");
  ASSERT_NE(intensity, nullptr);
  EXPECT_EQ(intensity->get(0), 10.0);
  EXPECT_EQ(placed.attributes().columns().size(), 1u);  // not the header's x and y
  // A header naming none of x, y and z converts when the columns are given.
  const std::string unnamed = "a b c\n1 2 3\n";
  vola_test::write_bytes(dir / "abc.xyz", std::vector<std::uint8_t>(unnamed.begin(), unnamed.end()));
  EXPECT_EQ(vola::convert((dir / "abc.xyz").string(), given).georef().bbox.min, (vola::Point{1, 2, 3}));
}

TEST(Convert, LasStreamsToTheTreeTheWholeCloudBuilds) {
  VOLA_REQUIRE_DATA(data);
  const std::string las = (data / "las" / "pdal_autzen_trim.las").string();
  vola::ConvertOptions o;
  o.voxel_size = 10.0;
  vola::ConvertReport report;
  const vola::Tree converted = vola::convert(las, o, {}, &report);
  EXPECT_EQ(report.format, "las");
  EXPECT_EQ(report.unit, "points");

  vola::io::LasReader reader(las);
  vola::BuildOptions b;
  b.quantization = vola::Quantization::grid;
  b.voxel_size = 10.0;
  b.epsg = converted.georef().epsg;
  const vola::Tree built = vola::build(vola::io::las_points(reader, true, false), b);
  EXPECT_EQ(report.build.points_in, reader.header().point_count);
  ASSERT_EQ(converted.voxel_count(), built.voxel_count());
  EXPECT_TRUE(std::equal(converted.words().begin(), converted.words().end(), built.words().begin(), built.words().end()));
  EXPECT_EQ(converted.frame(), built.frame());
  ASSERT_EQ(converted.attributes().size(), built.attributes().size());
  for (std::size_t a = 0; a < built.attributes().size(); ++a) {
    const auto& got = converted.attributes().columns()[a];
    const auto& want = built.attributes().columns()[a];
    ASSERT_EQ(got.name(), want.name());
    // Streamed means add chunk sums: equal up to rounding.
    for (std::size_t v = 0; v < want.size(); ++v)
      ASSERT_NEAR(got.get(v), want.get(v), 1e-6 * (1 + std::abs(want.get(v)))) << want.name() << " voxel " << v;
  }
}

// A bbox given with toolkit quantization clips the points outside it onto the border
// voxels, as the reference toolkit does (golden/fixed_bbox_clip): the same tree as the
// builder's, and a warning that counts them (the walls they make were a silent surprise).
TEST(Convert, AToolkitBboxClipsAsTheReferenceAndSaysSo) {
  VOLA_REQUIRE_DATA(data);
  const std::string las = (data / "las" / "pdal_autzen_trim.las").string();
  const vola::Box box{{636500, 849000, 400}, {637000, 849400, 520}};
  vola::ConvertOptions o;
  o.depth = 5;
  o.bbox = box;
  vola::ConvertReport report;
  const vola::Tree converted = vola::convert(las, o, {}, &report);
  EXPECT_EQ(converted.frame().quantization, vola::Quantization::toolkit);

  vola::io::LasReader reader(las);
  vola::PointCloud cloud = vola::io::las_points(reader, false, false);
  std::uint64_t outside = 0;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const double* p = cloud.xyz.data() + 3 * i;
    bool in = true;
    for (int a = 0; a < 3; ++a) in = in && p[a] >= box.min[a] && p[a] <= box.max[a];
    outside += in ? 0 : 1;
  }
  ASSERT_GT(outside, 1000u);  // the box cuts the survey
  vola::BuildOptions b;
  b.quantization = vola::Quantization::toolkit;
  b.depth = 5;
  b.bbox = box;
  const vola::Tree built = vola::build(cloud, b);
  ASSERT_EQ(converted.voxel_count(), built.voxel_count());
  EXPECT_TRUE(
      std::equal(converted.words().begin(), converted.words().end(), built.words().begin(), built.words().end()));
  ASSERT_EQ(report.warnings.size(), 1u);
  EXPECT_NE(report.warnings[0].find(std::to_string(outside) + " of its 110000 points lie outside the bbox"),
            std::string::npos)
      << report.warnings[0];
  o.bbox = vola::Box{{636000, 848900, 400}, {637200, 849500, 530}};  // holds every point: nothing to say
  vola::ConvertReport holds;
  vola::convert(las, o, {}, &holds);
  EXPECT_TRUE(holds.warnings.empty()) << holds.warnings[0];
}

// Reprojected into metres, the height column is in metres too: each voxel's mean height
// lies inside the voxel's own vertical extent (Autzen in feet kept heights in feet).
TEST(Convert, ReprojectedHeightsAreInTheTargetsUnits) {
  VOLA_REQUIRE_DATA(data);
  vola::ConvertOptions options;
  options.target_crs = "EPSG:32610";
  options.voxel_size = 2.0;
  vola::ConvertReport report;
  const vola::Tree tree = vola::convert((data / "las" / "pdal_autzen_trim.las").string(), options, {}, &report);
  // Neither CRS has a vertical axis: z stays in feet under a CRS in metres, as PROJ and
  // PDAL leave it, and the user is told so (the tiled survey mixed 124 m with 406 "m").
  ASSERT_EQ(report.warnings.size(), 1u);
  EXPECT_NE(report.warnings[0].find("heights (z) stay in foot while x and y go to metre"), std::string::npos)
      << report.warnings[0];
  // To a compound target the source (no vertical part) gives PROJ nothing to convert z
  // from: the heights stayed in feet labelled NAVD88 metres, and nothing was said.
  options.target_crs = "EPSG:32610+5703";
  vola::ConvertReport compound_target;
  vola::convert((data / "las" / "pdal_autzen_trim.las").string(), options, {}, &compound_target);
  ASSERT_EQ(compound_target.warnings.size(), 1u);
  EXPECT_NE(compound_target.warnings[0].find("heights (z) stay in foot though the target says metre (NAVD88 height)"),
            std::string::npos)
      << compound_target.warnings[0];
  // A compound CRS assigned to the file gives PROJ the heights' unit: they are converted,
  // and nothing is said (the warning read the file's own 2D CRS, not the assigned one).
  options.assign_crs = "EPSG:2994+6360";
  vola::ConvertReport assigned;
  const vola::Tree assigned_tree =
      vola::convert((data / "las" / "pdal_autzen_trim.las").string(), options, {}, &assigned);
  EXPECT_TRUE(assigned.warnings.empty()) << assigned.warnings[0];
  EXPECT_LT(assigned_tree.georef().bbox.max[2], 200.0);  // 520 ft is 158 m
  options.assign_crs.clear();
  // To degrees, metres stay what a geographic 2D CRS's heights are: nothing to say.
  options.target_crs = "EPSG:4326";
  options.allow_geographic = true;
  vola::ConvertReport to_degrees;
  vola::convert((data / "las" / "pdal_autzen-utm.las").string(), options, {}, &to_degrees);
  for (const std::string& w : to_degrees.warnings) EXPECT_EQ(w.find("heights (z)"), std::string::npos) << w;
  options.allow_geographic = false;
  options.target_crs = "EPSG:2994";  // the file's own unit: nothing to say
  vola::ConvertReport same_unit;
  vola::convert((data / "las" / "pdal_autzen_trim.las").string(), options, {}, &same_unit);
  EXPECT_TRUE(same_unit.warnings.empty()) << same_unit.warnings[0];
  const vola::AttributeColumn* height = tree.attributes().find("height");
  ASSERT_NE(height, nullptr);
  const vola::Frame frame = tree.frame();
  std::uint64_t rank = 0, outside = 0;
  tree.for_each_voxel([&](const vola::Voxel& v) {
    const double bottom = frame.origin[2] + v.z * frame.voxel_size;
    const double h = height->get(rank++);
    if (!(h >= bottom - 1e-3 && h <= bottom + frame.voxel_size + 1e-3)) ++outside;
  });
  EXPECT_EQ(outside, 0u) << "of " << tree.voxel_count() << " voxels";

  // A compound source (NAD83 / Oregon Lambert in metres + NAVD88 heights in US survey
  // feet) to a target without a vertical part: PROJ leaves z in feet under a metre CRS,
  // and said nothing; to a compound target the heights are converted, and nothing is said.
  const std::string bmx = (data / "las" / "pdal_autzen-bmx-2010.las").string();
  options.target_crs = "EPSG:32610";
  vola::ConvertReport compound;
  vola::convert(bmx, options, {}, &compound);
  ASSERT_EQ(compound.warnings.size(), 1u);
  EXPECT_NE(compound.warnings[0].find("heights (z) stay in US survey foot"), std::string::npos) << compound.warnings[0];
  EXPECT_NE(compound.warnings[0].find("go to metre"), std::string::npos) << compound.warnings[0];
  options.target_crs = "EPSG:32610+5703";
  vola::ConvertReport converted_heights;
  vola::convert(bmx, options, {}, &converted_heights);
  EXPECT_TRUE(converted_heights.warnings.empty()) << converted_heights.warnings[0];
  // Voxelised in its own CRS, a voxel is 2 m across and 2 US survey feet high: said.
  options.target_crs.clear();
  vola::ConvertReport native;
  vola::convert(bmx, options, {}, &native);
  ASSERT_EQ(native.warnings.size(), 1u);
  EXPECT_NE(native.warnings[0].find("heights are in US survey foot"), std::string::npos) << native.warnings[0];
  EXPECT_NE(native.warnings[0].find("not a cube"), std::string::npos) << native.warnings[0];
}

TEST(Convert, VoxelGridsMapCellForCellAndPointsNeedAGrid) {
  VOLA_REQUIRE_DATA(data);
  const vola::Tree chair = vola::convert((data / "binvox" / "trimesh_chair_model.binvox").string(), {});
  EXPECT_GT(chair.voxel_count(), 0u);
  EXPECT_EQ(chair.frame().quantization, vola::Quantization::grid);
  EXPECT_EQ(refused_option([&] { vola::convert((data / "ply" / "pdal_simple_text.ply").string(), {}); }),
            "voxel_size");
  vola::ConvertOptions solid;
  solid.solid = true;
  solid.voxel_size = 1.0;
  EXPECT_EQ(refused_option([&] { vola::convert((data / "ply" / "pdal_simple_text.ply").string(), solid); }), "solid");
  // The text reader's options are refused for other inputs, not ignored.
  const std::string las = (data / "las" / "pdal_autzen_pf1.las").string();
  vola::ConvertOptions columns;
  columns.voxel_size = 1.0;
  columns.columns = {4, 5, 6};
  EXPECT_EQ(refused_option([&] { vola::convert(las, columns); }), "columns");
  vola::ConvertOptions skip;
  skip.voxel_size = 1.0;
  skip.skip_lines = 1;
  EXPECT_EQ(refused_option([&] { vola::convert(las, skip); }), "skip_lines");
  vola::ConvertOptions payload;
  payload.voxel_size = 1.0;
  payload.payload_columns = {4};
  EXPECT_EQ(refused_option([&] { vola::convert(las, payload); }), "payload_columns");
}

// A voxel grid converted at a finer voxel size fills its cells: every voxel whose centre
// lies in an occupied cell is set, and every voxel set touches one (cell centres alone
// gave 1,002 isolated voxels for binvox-rw's chair at 0.5, cells of 1.285).
TEST(Convert, VoxelGridsAtAFinerVoxelSizeFillTheirCells) {
  VOLA_REQUIRE_DATA(data);
  const std::string chair = (data / "binvox" / "binvoxrw_chair.binvox").string();
  const vola::Tree cells = vola::convert(chair, {});
  const vola::Frame c = cells.frame();
  vola::ConvertOptions fine;
  fine.voxel_size = 0.5;
  const vola::Tree tree = vola::convert(chair, fine);
  const vola::Frame f = tree.frame();
  const auto cell_of = [&](double x, double y, double z) -> std::optional<vola::Voxel> {
    const double p[3] = {x, y, z};
    std::uint32_t v[3];
    for (int a = 0; a < 3; ++a) {
      const double i = std::floor((p[a] - c.origin[a]) / c.voxel_size);
      if (i < 0 || i >= cells.side()) return std::nullopt;
      v[a] = static_cast<std::uint32_t>(i);
    }
    return vola::Voxel{v[0], v[1], v[2]};
  };
  std::uint64_t touching = 0;
  tree.for_each_voxel([&](const vola::Voxel& v) {
    bool touches = false;  // a corner or the centre of the voxel in an occupied cell
    for (double dx : {0.01, 0.5, 0.99})
      for (double dy : {0.01, 0.5, 0.99})
        for (double dz : {0.01, 0.5, 0.99})
          if (const auto cell =
                  cell_of(f.origin[0] + (v.x + dx) * f.voxel_size, f.origin[1] + (v.y + dy) * f.voxel_size,
                          f.origin[2] + (v.z + dz) * f.voxel_size))
            touches = touches || cells.contains(*cell);
    touching += touches;
  });
  EXPECT_EQ(touching, tree.voxel_count());
  std::uint32_t n[3];  // the fine voxels over the cells' grid
  for (int a = 0; a < 3; ++a)
    n[a] = std::min<std::uint32_t>(
        tree.side(), static_cast<std::uint32_t>(
                         std::ceil((c.origin[a] + cells.side() * c.voxel_size - f.origin[a]) / f.voxel_size)));
  std::uint64_t holes = 0, inside = 0;
  for (std::uint32_t z = 0; z < n[2]; ++z)
    for (std::uint32_t y = 0; y < n[1]; ++y)
      for (std::uint32_t x = 0; x < n[0]; ++x) {
        const auto cell = cell_of(f.origin[0] + (x + 0.5) * f.voxel_size, f.origin[1] + (y + 0.5) * f.voxel_size,
                                  f.origin[2] + (z + 0.5) * f.voxel_size);
        if (!cell || !cells.contains(*cell)) continue;
        ++inside;
        holes += !tree.contains({x, y, z});
      }
  EXPECT_GT(inside, 10u * cells.voxel_count());
  EXPECT_EQ(holes, 0u);
}

}  // namespace

// --assign-crs relabels with any definition (a WKT with no code too) and says so when the
// input states another CRS; the points do not move.
TEST(Convert, AssignCrsRelabelsAnyDefinitionWithAWarning) {
  VOLA_REQUIRE_DATA(data);
  const std::string las = (data / "las" / "pdal_autzen_trim.las").string();
  vola::ConvertOptions plain;
  plain.voxel_size = 10.0;
  const vola::Tree stated = vola::convert(las, plain);

  vola::ConvertOptions utm = plain;
  utm.assign_crs = "EPSG:32610";
  vola::ConvertReport report;
  const vola::Tree relabelled = vola::convert(las, utm, {}, &report);
  EXPECT_EQ(report.epsg, 32610u);
  EXPECT_EQ(relabelled.georef().epsg, 32610u);
  EXPECT_EQ(relabelled.frame().origin, stated.frame().origin);  // nothing moved
  EXPECT_EQ(relabelled.voxel_count(), stated.voxel_count());
  ASSERT_EQ(report.warnings.size(), 1u);
  EXPECT_NE(report.warnings[0].find("relabels its coordinates without moving them"), std::string::npos);

  // A custom WKT (no EPSG code) is kept as the file's CRS; the same CRS draws no warning.
  vola::ConvertOptions same = plain;
  same.assign_crs = stated.georef().crs_wkt;
  vola::ConvertReport same_report;
  const vola::Tree kept = vola::convert(las, same, {}, &same_report);
  EXPECT_TRUE(same_report.warnings.empty());
  EXPECT_TRUE(vola::geo::same_crs(kept.georef().crs_wkt, stated.georef().crs_wkt));

  vola::ConvertOptions both = utm;
  both.epsg = 32610;
  EXPECT_EQ(refused_option([&] { vola::convert(las, both); }), "assign_crs");
  // A CRS PROJ does not know is the option's fault, named as such (C: INVALID_ARGUMENT).
  vola::ConvertOptions unknown = plain;
  unknown.assign_crs = "EPSG:999999";
  EXPECT_EQ(refused_option([&] { vola::convert(las, unknown); }), "assign_crs");
  unknown.assign_crs.clear();
  unknown.epsg = 999999;
  EXPECT_EQ(refused_option([&] { vola::convert(las, unknown); }), "epsg");

  // Names are not definitions: PROJ matches them loosely ("wgs" is WGS 72, "foo"
  // Amersfoort), so they are refused with PROJ's guess named.
  for (const char* name : {"wgs", "foo", "UTM zone 10N"}) {
    vola::ConvertOptions named = plain;
    named.assign_crs = name;
    try {
      vola::convert(las, named);
      ADD_FAILURE() << name << " was taken as a CRS";
    } catch (const vola::InvalidArgument& e) {
      EXPECT_NE(std::string(e.what()).find("is not a CRS definition"), std::string::npos) << e.what();
    }
  }
  vola::ConvertOptions wgs = plain;
  wgs.target_crs = "wgs";
  try {
    vola::convert(las, wgs);
    ADD_FAILURE() << "wgs was taken as a target CRS";
  } catch (const vola::InvalidArgument& e) {
    EXPECT_NE(std::string(e.what()).find("PROJ would guess WGS 72"), std::string::npos) << e.what();
  }
  // A PROJ string is a CRS without +type=crs too (PROJ alone takes it for an operation).
  vola::ConvertOptions proj_string = plain;
  proj_string.target_crs = "+proj=utm +zone=10 +datum=WGS84";
  EXPECT_GT(vola::convert(las, proj_string).voxel_count(), 0u);
}

// Grid voxels in degrees are refused unless reprojected or allowed; the toolkit's
// quantization (which fits any box) only warns.
TEST(Convert, GeographicGridVoxelsAreRefusedUnlessAllowed) {
  VOLA_REQUIRE_DATA(data);
  const std::string las = (data / "las" / "pdal_epsg_4326.las").string();
  vola::ConvertOptions grid;
  grid.voxel_size = 0.001;
  // About no one option the user gave (the CLI printed "--target-crs:" before it): the
  // cause names both ways out for the front end to spell.
  try {
    vola::convert(las, grid);
    ADD_FAILURE() << "geographic grid voxels were not refused";
  } catch (const vola::OptionError& e) {
    EXPECT_EQ(e.option(), "");
    EXPECT_NE(e.cause().find("`target_crs`"), std::string::npos) << e.cause();
    EXPECT_NE(e.cause().find("`allow_geographic`"), std::string::npos) << e.cause();
    EXPECT_EQ(std::string(e.what()), e.cause());
  }

  vola::ConvertOptions allowed = grid;
  allowed.allow_geographic = true;
  vola::ConvertReport report;
  EXPECT_GT(vola::convert(las, allowed, {}, &report).voxel_count(), 0u);
  ASSERT_EQ(report.warnings.size(), 1u);
  EXPECT_NE(report.warnings[0].find("geographic"), std::string::npos);

  vola::ConvertOptions moved = grid;
  moved.voxel_size = 1.0;
  moved.target_crs = "32615";
  vola::ConvertReport moved_report;
  EXPECT_GT(vola::convert(las, moved, {}, &moved_report).voxel_count(), 0u);
  EXPECT_TRUE(moved_report.warnings.empty());

  vola::ConvertOptions toolkit;
  toolkit.quantization = vola::Quantization::toolkit;
  toolkit.depth = 4;
  vola::ConvertReport toolkit_report;
  EXPECT_NO_THROW(vola::convert(las, toolkit, {}, &toolkit_report));
  EXPECT_EQ(toolkit_report.warnings.size(), 1u);

  // A projected file assigned a geographic CRS is refused the same way.
  vola::ConvertOptions relabelled;
  relabelled.voxel_size = 10.0;
  relabelled.assign_crs = "4326";
  EXPECT_THROW(vola::convert((data / "las" / "pdal_autzen_trim.las").string(), relabelled), vola::OptionError);
  // A RiSCAN export whose keys say geocentric WGS 84 (GTModelType 3 on code 4326, as GDAL
  // and PDAL read them) over UTM-sized metres (x 515393): converted, with a warning that
  // the label is likely wrong (the points lie ~4900 km from the earth's centre)...
  vola::ConvertOptions mislabelled;
  mislabelled.voxel_size = 10.0;
  vola::ConvertReport mislabelled_report;
  vola::convert((data / "laz" / "pdal_lone-star-split-1.laz").string(), mislabelled, {}, &mislabelled_report);
  ASSERT_EQ(mislabelled_report.warnings.size(), 1u);
  EXPECT_NE(mislabelled_report.warnings[0].find("km from the earth's centre, not near its surface"), std::string::npos)
      << mislabelled_report.warnings[0];
  EXPECT_NE(mislabelled_report.warnings[0].find("a geocentric CRS: the CRS label is likely wrong"), std::string::npos)
      << mislabelled_report.warnings[0];
  // ... and refused when reprojecting from it, where PROJ would put the points on the
  // equator (or fail) with a message naming nothing to fix.
  vola::ConvertOptions refused;
  refused.voxel_size = 10.0;
  refused.target_crs = "EPSG:32610";
  try {
    vola::convert((data / "laz" / "pdal_lone-star-split-1.laz").string(), refused);
    ADD_FAILURE() << "the mislabelled file was reprojected";
  } catch (const vola::OptionError& e) {
    EXPECT_NE(e.cause().find("the CRS label is likely wrong"), std::string::npos) << e.cause();
    EXPECT_NE(e.cause().find("to reproject from"), std::string::npos) << e.cause();
  }
  // Earth-centred points under a geocentric CRS: placed by all three coordinates (the
  // header's latitude was 0, computed with z = 0), and no warning.
  {
    vola_test::TempDir dir;
    const auto path = dir / "ecef.xyz";
    const double lat = 45.0 * std::numbers::pi / 180, lon = 7.0 * std::numbers::pi / 180;
    const double a = 6378137.0, e2 = 6.69437999014e-3, n = a / std::sqrt(1 - e2 * std::sin(lat) * std::sin(lat));
    std::ofstream out(path);
    out.precision(17);
    for (int k = 0; k < 3; ++k)
      out << n * std::cos(lat) * std::cos(lon) + k << ' ' << n * std::cos(lat) * std::sin(lon) << ' '
          << n * (1 - e2) * std::sin(lat) << '\n';
    out.close();
    vola::ConvertOptions ecef;
    ecef.voxel_size = 1.0;
    ecef.assign_crs = "4978";
    vola::ConvertReport ecef_report;
    const vola::Tree tree = vola::convert(path.string(), ecef, {}, &ecef_report);
    EXPECT_NEAR(tree.georef().lat, 45.0, 1e-4);
    EXPECT_NEAR(tree.georef().lon, 7.0, 1e-4);
    EXPECT_TRUE(ecef_report.warnings.empty()) << ecef_report.warnings.front();
  }
  // A geographic target is the target's fault, not the file's (which is in feet).
  vola::ConvertOptions to_degrees;
  to_degrees.voxel_size = 3.0;
  to_degrees.target_crs = "EPSG:4326";
  try {
    vola::convert((data / "las" / "pdal_autzen_trim.las").string(), to_degrees);
    ADD_FAILURE() << "a geographic target was not refused";
  } catch (const vola::OptionError& e) {
    EXPECT_EQ(e.option(), "target_crs");
    EXPECT_NE(e.cause().find("'EPSG:4326' is WGS 84, a geographic CRS"), std::string::npos) << e.cause();
    EXPECT_EQ(e.cause().find("pdal_autzen_trim"), std::string::npos) << e.cause();
  }
  EXPECT_TRUE(vola::is_geographic_crs("EPSG:4979"));
  EXPECT_FALSE(vola::is_geographic_crs("EPSG:32610"));
}

namespace {

std::string convert_error(const std::string& path, const vola::ConvertOptions& options) {
  try {
    vola::convert(path, options);
  } catch (const vola::OptionError& e) {
    return std::string("OptionError ") + e.what();
  } catch (const vola::InvalidArgument& e) {
    return e.what();
  }
  return "(converted)";
}

// Finite points whose extent overflows a double (-1e308 .. 1e308) all fell into voxel 0
// with NaN centres, exit 0, under toolkit quantization; a grid too large for any depth
// blamed --depth, which was not given. Each is refused naming the file.
TEST(Convert, ACentreOutsideTheCrsDomainHasInfiniteLatLonAsTheReferenceWrites) {
  // EPSG:2000 (the reference's default) cannot place x = 1e9: PROJ returns no position,
  // and the reference toolkit writes pyproj's +inf for lat and lon. vola writes the same
  // file (it refused the conversion before) and, for a CRS the user gave, says why.
  vola_test::TempDir dir;
  const auto path = dir / "far.xyz";
  std::ofstream(path) << "1000000000.5 1000000000.25 3\n1000000999.0 1000000299.5 20\n";
  for (const bool given : {true, false}) {
    vola::ConvertOptions options;
    options.depth = 3;
    options.quantization = vola::Quantization::toolkit;
    if (given) options.assign_crs = "2000";
    vola::ConvertReport report;
    const vola::Tree tree = vola::convert(path.string(), options, {}, &report);
    EXPECT_EQ(tree.georef().lat, std::numeric_limits<double>::infinity());
    EXPECT_EQ(tree.georef().lon, std::numeric_limits<double>::infinity());
    EXPECT_EQ(tree.voxel_count(), 2u);
    const bool warned = std::any_of(report.warnings.begin(), report.warnings.end(), [](const std::string& w) {
      return w.find("(1000000500, 1000000150) lies outside the domain of EPSG:2000") != std::string::npos &&
             w.find("lat/lon are inf") != std::string::npos;
    });
    EXPECT_EQ(warned, given) << (report.warnings.empty() ? "" : report.warnings.front());
  }
}

TEST(Convert, GridsThePointsCannotBePutOnAreRefusedNamingTheFile) {
  vola_test::TempDir dir;
  const std::string overflow = (dir / "overflow.xyz").string();
  const std::string text = "-1e308 0 0\n1e308 1 1\n4 5 6\n";
  vola_test::write_bytes(overflow, std::vector<std::uint8_t>(text.begin(), text.end()));
  vola::ConvertOptions toolkit;
  toolkit.quantization = vola::Quantization::toolkit;
  toolkit.depth = 2;
  EXPECT_EQ(convert_error(overflow, toolkit).rfind(overflow + ": toolkit quantization cannot scale", 0), 0u)
      << convert_error(overflow, toolkit);
  vola::ConvertOptions grid;
  grid.voxel_size = 1;
  EXPECT_EQ(convert_error(overflow, grid).rfind(overflow + ": an extent of", 0), 0u) << convert_error(overflow, grid);
  // A binvox grid wider than depth 10's 4^10 cells, without --depth.
  const std::string wide = (dir / "wide.binvox").string();
  const std::string binvox = "#binvox 1\ndim 1048577 1 1\ntranslate 0 0 0\nscale 1\ndata\n";
  std::vector<std::uint8_t> bytes(binvox.begin(), binvox.end());
  for (int run = 0; run < 4112; ++run) bytes.insert(bytes.end(), {1, 255});
  bytes.insert(bytes.end(), {1, 17});  // 4112 * 255 + 17 = 1048577 cells
  vola_test::write_bytes(wide, bytes);
  EXPECT_EQ(convert_error(wide, {}), wide + ": a 1048577-cell grid does not fit depth 10 (1048576 voxels per axis), the deepest a tree has");
  vola::ConvertOptions depth3;
  depth3.depth = 3;
  EXPECT_EQ(convert_error(wide, depth3).rfind("OptionError depth: a 1048577-cell grid does not fit depth 3", 0), 0u);
}

}  // namespace

namespace {

std::vector<std::array<double, 3>> centres(const vola::Tree& tree) {
  std::vector<std::array<double, 3>> out;
  const vola::Frame frame = tree.frame();
  tree.for_each_voxel([&](const vola::Voxel& v) {
    out.push_back({frame.origin[0] + (v.x + 0.5) * frame.voxel_size, frame.origin[1] + (v.y + 0.5) * frame.voxel_size,
                   frame.origin[2] + (v.z + 0.5) * frame.voxel_size});
  });
  std::sort(out.begin(), out.end());
  return out;
}

// A header naming x, y and z placed them only when no column option was given: with
// --attribute or --nbits, x and z of "z,y,x" were swapped (exit 0). --no-attributes kept
// the header's other columns.
TEST(Convert, TextHeadersPlaceXyzWhateverColumnsAreKept) {
  vola_test::TempDir dir;
  const std::string zyx = (dir / "zyx.csv").string();
  const std::string text = "z,y,x,intensity\n3,2,1,7\n6,5,4,9\n";
  vola_test::write_bytes(zyx, std::vector<std::uint8_t>(text.begin(), text.end()));
  vola::ConvertOptions options;
  options.voxel_size = 1;
  const auto expected = std::vector<std::array<double, 3>>{{1.5, 2.5, 3.5}, {4.5, 5.5, 6.5}};
  EXPECT_EQ(centres(vola::convert(zyx, options)), expected);
  options.text_attributes = {"intensity=4"};
  const vola::Tree kept = vola::convert(zyx, options);
  EXPECT_EQ(centres(kept), expected);
  EXPECT_EQ(kept.attributes().size(), 1u);
  options.text_attributes.clear();
  options.attributes = false;
  const vola::Tree bare = vola::convert(zyx, options);
  EXPECT_EQ(centres(bare), expected);
  EXPECT_EQ(bare.attributes().size(), 0u);
  // Columns given explicitly still win over the header.
  options.attributes = true;
  options.columns = {3, 2, 4};
  EXPECT_EQ(centres(vola::convert(zyx, options)),
            (std::vector<std::array<double, 3>>{{1.5, 2.5, 7.5}, {4.5, 5.5, 9.5}}));
  // --nbits 1: the payload bytes are the columns other than x, y and z.
  const std::string rgbxyz = (dir / "rgbxyz.xyz").string();
  const std::string coloured = "r g b x y z\n10 20 30 1 1 1\n40 50 60 5 5 5\n";
  vola_test::write_bytes(rgbxyz, std::vector<std::uint8_t>(coloured.begin(), coloured.end()));
  vola::ConvertOptions payload;
  payload.voxel_size = 1;
  payload.nbits = 1;
  const vola::Tree with_payload = vola::convert(rgbxyz, payload);
  EXPECT_EQ(centres(with_payload), (std::vector<std::array<double, 3>>{{1.5, 1.5, 1.5}, {5.5, 5.5, 5.5}}));
  ASSERT_EQ(with_payload.voxel_payloads().size(), 2u);
  EXPECT_EQ(with_payload.voxel_payloads()[0], 0x1e140aull);  // 10, 20, 30
  // Nine columns after x y z do not fit the word: refused (the reference overflows and
  // writes nothing) rather than the ninth dropped unsaid; named columns still convert.
  const std::string nine = (dir / "nine.xyz").string();
  const std::string nine_text = "1 1 1 1 2 3 4 5 6 7 8 9\n";
  vola_test::write_bytes(nine, std::vector<std::uint8_t>(nine_text.begin(), nine_text.end()));
  payload.nbits = 2;
  try {
    vola::convert(nine, payload);
    ADD_FAILURE() << "nine payload columns were converted";
  } catch (const vola::OptionError& e) {
    EXPECT_EQ(e.option(), "nbits");
    EXPECT_NE(e.cause().find("has 9 columns besides x, y and z"), std::string::npos) << e.cause();
  }
  payload.payload_columns = {4, 5, 6, 7, 8, 9, 10, 11};
  const vola::Tree eight = vola::convert(nine, payload);
  ASSERT_EQ(eight.voxel_payloads().size(), 1u);
  EXPECT_EQ(eight.voxel_payloads()[0], 0x0807060504030201ull);
}

TEST(Convert, ValuesAnIntegerAttributeCannotHoldAreSaid) {
  vola_test::TempDir dir;
  const std::string path = (dir / "values.xyz").string();
  const std::string text = "0 0 0 300\n5 5 5 -4\n9 9 9 7\n3 3 3 nan\n";
  vola_test::write_bytes(path, std::vector<std::uint8_t>(text.begin(), text.end()));
  vola::ConvertOptions options;
  options.voxel_size = 1;
  options.text_attributes = {"a=4:u8"};
  vola::ConvertReport report;
  const vola::Tree tree = vola::convert(path, options, {}, &report);
  const vola::AttributeColumn* a = tree.attributes().find("a");
  ASSERT_NE(a, nullptr);
  EXPECT_EQ(a->get(*tree.rank({0, 0, 0})), 255);  // clamped, as the warning says
  ASSERT_EQ(report.warnings.size(), 2u);
  EXPECT_EQ(report.warnings[0], path + ": attribute a: 2 of 4 values lie outside u8's range 0..255 (from -4 to 300): "
                                       "they are stored clamped to it; give the attribute a wider TYPE (f32, i32, ...)");
  EXPECT_EQ(report.warnings[1], path + ": attribute a: 1 of 4 values are not numbers: u8 stores them as 0");
  // The same values as i16, and as the default f32: nothing to say.
  for (const std::string spec : {"a=4:i16", "a=4"}) {
    options.text_attributes = {spec};
    vola::convert(path, options, {}, &report);
    EXPECT_EQ(report.warnings.size(), spec == "a=4" ? 0u : 1u) << spec;  // i16 still has no NaN
  }
}

// An EPT dataset converted on a grid its bbox fixes: the nodes whose cube misses the grid
// are not read (the report's bytes say so), and the voxels are those of the whole read.
TEST(Convert, AGridBboxSkipsTheEptNodesOutsideIt) {
  const vola_test::TempDir dir;
  const auto text = [&](const std::filesystem::path& path, const std::string& content) {
    std::filesystem::create_directories(path.parent_path());
    std::ofstream(path, std::ios::binary) << content;
  };
  text(dir / "ept.json",
       "{\"bounds\": [0, 0, 0, 8, 8, 8], \"dataType\": \"binary\", \"hierarchyType\": \"json\", \"points\": 3, "
       "\"schema\": [{\"name\": \"X\", \"size\": 8, \"type\": \"float\"}, {\"name\": \"Y\", \"size\": 8, \"type\": "
       "\"float\"}, {\"name\": \"Z\", \"size\": 8, \"type\": \"float\"}], \"span\": 128, \"version\": \"1.0.0\"}");
  text(dir / "ept-hierarchy" / "0-0-0-0.json", "{\"0-0-0-0\": 1, \"1-0-0-0\": 1, \"1-1-1-1\": 1}");
  for (const auto& [key, at] : {std::pair{"0-0-0-0", 1.0}, std::pair{"1-0-0-0", 2.0}, std::pair{"1-1-1-1", 6.0}}) {
    std::string record;
    for (int a = 0; a < 3; ++a) record.append(reinterpret_cast<const char*>(&at), sizeof at);
    text(dir / "ept-data" / (std::string(key) + ".bin"), record);
  }
  const std::string ept = (dir / "ept.json").string();
  vola::ConvertOptions options;
  options.voxel_size = 0.5;
  options.bbox = vola::Box{{5, 5, 5}, {7, 7, 7}};
  vola::ConvertReport window;
  const vola::Tree tree = vola::convert(ept, options, {}, &window);
  ASSERT_TRUE(window.bytes_read && window.bytes_total);
  EXPECT_EQ(*window.bytes_read, 48u);  // the root and 1-1-1-1
  EXPECT_EQ(*window.bytes_total, 72u);
  EXPECT_EQ(window.build.points_in, 2u);
  // The same grid with a filter reads every node (filters see the points around the window).
  options.filters = {"where:Z >= 0"};
  vola::ConvertReport whole;
  const vola::Tree same = vola::convert(ept, options, {}, &whole);
  EXPECT_EQ(whole.build.points_in, 3u);
  const auto voxels = [](const vola::Tree& t) {
    std::vector<vola::Voxel> out;
    t.for_each_voxel([&](const vola::Voxel& v) { out.push_back(v); });
    return out;
  };
  EXPECT_EQ(tree.voxel_count(), 1u);
  EXPECT_EQ(voxels(tree), voxels(same));
  EXPECT_EQ(tree.frame(), same.frame());
}

// An E57 whose coordinateMetadata is an EPSG code PROJ does not know stopped `vola
// convert` with "CRS EPSG:99999999 is not known to PROJ" and no file named; the code is
// now left out with a warning, as an unreadable WKT is.
TEST(Convert, AnEpsgCodeProjDoesNotKnowIsLeftOutWithAWarning) {
  vola_test::TempDir dir;
  vola_io_test::E57TestScan scan;
  for (const char* axis : {"cartesianX", "cartesianY", "cartesianZ"})
    scan.fields.push_back({axis, "Float", false, 0, 0, 1.0, 0.0, {0.0, 1.0, 2.0}});
  const auto path = dir / "unknown_code.e57";
  vola_test::write_bytes(path, vola_io_test::e57_test_file({scan}, "EPSG:99999999"));
  vola::ConvertOptions options;
  options.voxel_size = 1.0;
  vola::ConvertReport report;
  vola::Tree tree;
  ASSERT_NO_THROW(tree = vola::convert(path.string(), options, {}, &report));
  const bool warned = std::any_of(report.warnings.begin(), report.warnings.end(), [](const std::string& w) {
    return w.find("unknown_code.e57: its CRS, EPSG:99999999, is not a code PROJ knows: it is not kept") !=
           std::string::npos;
  });
  EXPECT_TRUE(warned);
  EXPECT_FALSE(report.epsg);
  EXPECT_EQ(tree.voxel_count(), 3u);
}

}  // namespace
