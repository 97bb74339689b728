// Text points whose first line names the columns, as PDAL's writers.text, CloudCompare
// and vola export write them: the header is never a point, and it lays the columns out
// unless the caller does.
#include <gtest/gtest.h>

#include <chrono>
#include <fstream>
#include <string>
#include <vector>

#include "test_support.hpp"
#include "vola/error.hpp"
#include "vola/io/text_points.hpp"

namespace {

using vola_test::TempDir;

vola::PointCloud read_text(const TempDir& dir, const std::string& text, const vola::io::TextColumns& columns = {}) {
  const auto path = dir / "points.txt";
  std::ofstream(path, std::ios::binary) << text;
  return vola::io::read_text_points(path.string(), columns);
}

const vola::PointAttribute& column(const vola::PointCloud& cloud, const std::string& name) {
  for (const auto& a : cloud.attributes)
    if (a.name == name) return a;
  throw std::runtime_error("no column " + name);
}

std::vector<std::string> names(const vola::PointCloud& cloud) {
  std::vector<std::string> out;
  for (const auto& a : cloud.attributes) out.push_back(a.name);
  return out;
}

TEST(TextHeader, PdalsQuotedCsvNamesEveryColumn) {
  TempDir dir;
  // writers.text's default: quoted names, commas; LAS fields in PDAL's spelling; x, y
  // and z need not come first.
  const auto cloud = read_text(dir,
                               "\"Intensity\",\"Z\",\"X\",\"Y\",\"Classification\",\"ReturnNumber\",\"NumberOfReturns\","
                               "\"Red\",\"Green\",\"Blue\",\"GpsTime\"\n"
                               "10,3.5,1.25,2,2,1,2,65535,0,300,1000.5\n"
                               "20,6,4,5,6,2,2,0,128,0,1001\n");
  ASSERT_EQ(cloud.size(), 2u);
  EXPECT_EQ(cloud.xyz, (std::vector<double>{1.25, 2, 3.5, 4, 5, 6}));
  EXPECT_EQ(names(cloud), (std::vector<std::string>{"intensity", "classification", "return_number", "number_of_returns",
                                                    "red", "green", "blue", "gps_time"}));
  EXPECT_EQ(column(cloud, "classification").values, (std::vector<double>{2, 6}));
  EXPECT_EQ(column(cloud, "classification").reduction, vola::Reduction::majority);
  EXPECT_EQ(column(cloud, "number_of_returns").reduction, vola::Reduction::max);
  EXPECT_EQ(column(cloud, "gps_time").values, (std::vector<double>{1000.5, 1001}));
  // One colour beyond 255: 16-bit colours.
  EXPECT_EQ(column(cloud, "red").type, vola::ValueType::u16);
}

// pandas' DataFrame.to_csv writes its unnamed index column first (",x,y,z,..."), R's
// write.csv the same quoted (`"","x","y","z"`): the empty name is a column of its own,
// unread. Skipping it as a separator once put x on the index, y on x, z on y.
TEST(TextHeader, AnEmptyCsvNameIsAnUnnamedColumn) {
  TempDir dir;
  const std::string rows = "0,1.5,2.25,3.0,0\n1,4,5.5,6.75,10\n";
  for (const std::string& head :
       {std::string(",x,y,z,intensity\n"), std::string("\"\",\"x\",\"y\",\"z\",\"intensity\"\n"),
        std::string("index, x, y, z, intensity,\n")}) {
    SCOPED_TRACE(head);
    const auto cloud = read_text(dir, head + rows);
    ASSERT_EQ(cloud.size(), 2u);
    EXPECT_EQ(cloud.xyz, (std::vector<double>{1.5, 2.25, 3.0, 4, 5.5, 6.75}));
    EXPECT_EQ(column(cloud, "intensity").values, (std::vector<double>{0, 10}));
  }
}

// Identifiers and labels are reduced by majority, as classes are: lidR's treeID, PDAL's
// EPT OriginId, segmentation output; the mean of two tree ids is a third tree. A name
// that merely ends in "id" (geoid, centroid) is a measurement and keeps the mean.
TEST(TextHeader, IdentifierColumnsTakeTheMajorityOfAVoxel) {
  TempDir dir;
  const auto cloud = read_text(dir,
                               "x y z treeID tree_id OriginId ID cluster-id segment3ID cluster instance "
                               "geoid centroid paid temperature\n"
                               "1 2 3 4 5 6 7 8 9 10 11 12 13 14 15\n");
  for (const char* id : {"treeid", "tree_id", "originid", "id", "cluster-id", "segment3id", "cluster", "instance"})
    EXPECT_EQ(column(cloud, id).reduction, vola::Reduction::majority) << id;
  for (const char* value : {"geoid", "centroid", "paid", "temperature"})
    EXPECT_EQ(column(cloud, value).reduction, vola::Reduction::mean) << value;
}

// A quoted name may hold spaces (CloudCompare's M3C2 output, re-written by PDAL): the
// quotes, not the spaces, delimit it, so the names line up with the values.
TEST(TextHeader, QuotedNamesMayHoldSpaces) {
  TempDir dir;
  const auto cloud = read_text(dir, "\"X\",\"Y\",\"Z\",\"M3C2 distance\",'significant change',\"Intensity\"\n"
                                    "1.5,2.5,3.5,0.25,1,100\n4,5,6,-0.5,0,200\n");
  ASSERT_EQ(cloud.size(), 2u);
  EXPECT_EQ(names(cloud), (std::vector<std::string>{"m3c2 distance", "significant change", "intensity"}));
  EXPECT_EQ(column(cloud, "m3c2 distance").values, (std::vector<double>{0.25, -0.5}));
  EXPECT_EQ(column(cloud, "intensity").values, (std::vector<double>{100, 200}));
  // The column count (what --nbits 1 lays payload bytes out by) counts each name once.
  EXPECT_EQ(vola::io::count_text_columns((dir / "points.txt").string(), 0), 6);
}

TEST(TextHeader, CommentHeadersOfCloudCompareAndVolaExport) {
  TempDir dir;
  const auto cc = read_text(dir, "//X,Y,Z,R,G,B\n1,2,3,255,0,7\n4,5,6,0,10,0\n");
  EXPECT_EQ(cc.xyz, (std::vector<double>{1, 2, 3, 4, 5, 6}));
  EXPECT_EQ(names(cc), (std::vector<std::string>{"red", "green", "blue"}));
  // Text says no bit depth: the values go on as written (LAS gets 255, as from PDAL's
  // readers.text), u16.
  EXPECT_EQ(column(cc, "red").type, vola::ValueType::u16);
  EXPECT_EQ(column(cc, "blue").values, (std::vector<double>{7, 0}));
  // vola export's XYZ, after a descriptive comment: the names are on the second line.
  const auto own = read_text(dir, "# made by hand\n# x y z intensity classification\n0.5 1.5 2.5 7 2\n");
  EXPECT_EQ(own.xyz, (std::vector<double>{0.5, 1.5, 2.5}));
  EXPECT_EQ(names(own), (std::vector<std::string>{"intensity", "classification"}));
  // A comment of numbers or of other words names nothing.
  const auto plain = read_text(dir, "# 1 2 3\n# written by a scanner\n1 2 3 4\n");
  EXPECT_EQ(plain.xyz, (std::vector<double>{1, 2, 3}));
  EXPECT_TRUE(plain.attributes.empty());
}

TEST(TextHeader, NamesWithoutXyzAreRefusedUnlessTheColumnsAreGiven) {
  TempDir dir;
  try {
    read_text(dir, "# survey 7\nlat lon h\n1 2 3\n");
    FAIL() << "a header without x, y and z was taken";
  } catch (const vola::FormatError& e) {
    EXPECT_EQ(e.offset(), std::optional<std::uint64_t>{11});  // the names line's first byte
    EXPECT_NE(std::string(e.what()).find("line 2 names its columns but none of them x, y and z"), std::string::npos)
        << e.what();
  }
  vola::io::TextColumns given;
  given.from_header = false;
  given.x = 1, given.y = 0, given.z = 2;
  const auto cloud = read_text(dir, "lat lon h\n1 2 3\n", given);  // the names line is passed over
  EXPECT_EQ(cloud.xyz, (std::vector<double>{2, 1, 3}));
  // Columns given explicitly win over a header that names x, y and z too.
  const auto explicit_columns = read_text(dir, "x y z a\n1 2 3 4\n", given);
  EXPECT_EQ(explicit_columns.xyz, (std::vector<double>{2, 1, 3}));
  EXPECT_TRUE(explicit_columns.attributes.empty());
}

TEST(TextHeader, FilesWithoutOneReadAsBefore) {
  TempDir dir;
  const auto cloud = read_text(dir, "1 2 3 9\n4 5 6 9\n");
  EXPECT_EQ(cloud.xyz, (std::vector<double>{1, 2, 3, 4, 5, 6}));
  EXPECT_TRUE(cloud.attributes.empty());
  // A bad value on a later line is still a bad value, not a header.
  EXPECT_THROW(read_text(dir, "1 2 3\nx y z\n"), vola::FormatError);
}

// Open3D's write_point_cloud: .xyzn holds x y z nx ny nz, .xyzrgb x y z r g b with
// colours in 0..1, neither with a header line.
TEST(TextHeader, Open3DsExtensionsNameTheirColumns) {
  TempDir dir;
  const auto normals_path = dir / "cloud.xyzn";
  std::ofstream(normals_path, std::ios::binary) << "1 2 3 0 0 1\n4 5 6 0.6 0.8 0\n";
  const auto normals = vola::io::read_text_points(normals_path.string(), {});
  EXPECT_EQ(normals.xyz, (std::vector<double>{1, 2, 3, 4, 5, 6}));
  EXPECT_EQ(names(normals), (std::vector<std::string>{"nx", "ny", "nz"}));
  EXPECT_EQ(column(normals, "nx").values, (std::vector<double>{0, 0.6}));

  const auto colour_path = dir / "cloud.XYZRGB";
  std::ofstream(colour_path, std::ios::binary) << "1 2 3 1.0000000000 0.5000000000 0.0000000000\n4 5 6 0.2 0 1\n";
  const auto coloured = vola::io::read_text_points(colour_path.string(), {});
  EXPECT_EQ(coloured.xyz, (std::vector<double>{1, 2, 3, 4, 5, 6}));
  EXPECT_EQ(column(coloured, "red").values, (std::vector<double>{255, 51}));
  EXPECT_EQ(column(coloured, "green").values, (std::vector<double>{128, 0}));
  EXPECT_EQ(column(coloured, "blue").values, (std::vector<double>{0, 255}));
  EXPECT_EQ(column(coloured, "red").type, vola::ValueType::u8);
  // Colours past 1 are bytes already: kept, not clamped to 255.
  std::ofstream(colour_path, std::ios::binary) << "1 2 3 200 0.5 1\n";
  EXPECT_EQ(column(vola::io::read_text_points(colour_path.string(), {}), "red").values, (std::vector<double>{200}));
  EXPECT_EQ(column(vola::io::read_text_points(colour_path.string(), {}), "green").values, (std::vector<double>{0.5}));

  // A header line still wins over the extension.
  std::ofstream(colour_path, std::ios::binary) << "x y z intensity nx ny\n1 2 3 7 8 9\n";
  EXPECT_EQ(names(vola::io::read_text_points(colour_path.string(), {})),
            (std::vector<std::string>{"intensity", "nx", "ny"}));
}

}  // namespace

// Spreadsheets in most of Europe write decimal commas and separate fields by semicolons
// (or tabs): the commas are decimal marks there, not separators. Read as separators, the
// first line below gave the point (1, 5, 2) with exit 0.
TEST(TextDecimalComma, SemicolonAndTabFilesReadTheirCommasAsDecimalMarks) {
  TempDir dir;
  const auto semicolons = read_text(dir, "x;y;z;intensity\n1,5;2,25;-3,5;10\n4;5,75;6,0;20,5\n");
  EXPECT_EQ(semicolons.xyz, (std::vector<double>{1.5, 2.25, -3.5, 4, 5.75, 6}));
  EXPECT_EQ(column(semicolons, "intensity").values, (std::vector<double>{10, 20.5}));
  const auto tabs = read_text(dir, "1,5\t2,25\t3\n+4,125 5 6,5\n");
  EXPECT_EQ(tabs.xyz, (std::vector<double>{1.5, 2.25, 3, 4.125, 5, 6.5}));
  EXPECT_EQ(vola::io::count_text_columns((dir / "points.txt").string(), 0), 3);
  // Decided line by line: a first point of whole numbers says nothing about the next.
  const auto later = read_text(dir, "1;2;3\n1,5;2;3\n");
  EXPECT_EQ(later.xyz, (std::vector<double>{1, 2, 3, 1.5, 2, 3}));
  const auto tab_later = read_text(dir, "0\t0\t0\n1,5\t2,25\t3,75\n");  // was read as 1 5 2, exit 0
  EXPECT_EQ(tab_later.xyz, (std::vector<double>{0, 0, 0, 1.5, 2.25, 3.75}));
}

TEST(TextDecimalComma, PlainCsvKeepsCommasAsSeparators) {
  TempDir dir;
  EXPECT_EQ(read_text(dir, "1.5,2.25,3\n").xyz, (std::vector<double>{1.5, 2.25, 3}));
  EXPECT_EQ(read_text(dir, "1, 2, 3\n4 ,5 ,6\n").xyz, (std::vector<double>{1, 2, 3, 4, 5, 6}));
  EXPECT_EQ(read_text(dir, "1,2,3\n").xyz, (std::vector<double>{1, 2, 3}));
  EXPECT_EQ(vola::io::count_text_columns((dir / "points.txt").string(), 0), 3);
  EXPECT_EQ(read_text(dir, "10,20,30 40\n").xyz, (std::vector<double>{10, 20, 30}));  // two commas in a field
}

TEST(TextDecimalComma, AThousandsSeparatorIsAnErrorNotANumber) {
  TempDir dir;
  try {
    read_text(dir, "1.234,5;2;3\n");
    FAIL() << "1.234,5 was read as a number";
  } catch (const vola::FormatError& e) {
    EXPECT_NE(std::string(e.what()).find("line 1: column 1 '1.234,5' is not a number"), std::string::npos) << e.what();
  }
}

// A line with more columns than the first point's was read in part: the file's other
// points are not silently dropped or mixed up.
TEST(TextLines, EveryPointHasTheFirstPointsColumns) {
  TempDir dir;
  try {
    read_text(dir, "1 2 3\n4 5 6 7\n");
    FAIL() << "a line of four columns after one of three was read";
  } catch (const vola::FormatError& e) {
    EXPECT_NE(std::string(e.what()).find("line 2: has 4 columns where line 1, the first point, has 3"), std::string::npos)
        << e.what();
  }
  // Separators at the ends and doubled separators are no columns.
  EXPECT_EQ(read_text(dir, "1 2 3\n 4  5 6 \n7,8,9,\n").xyz, (std::vector<double>{1, 2, 3, 4, 5, 6, 7, 8, 9}));
}

// Lines ended by a carriage return alone (classic Mac OS, some instruments) were one line
// of every point's columns, read as the first point alone.
TEST(TextLines, CarriageReturnsAloneEndLines) {
  TempDir dir;
  EXPECT_EQ(read_text(dir, "1 2 3\r4 5 6\r7 8 9\r").xyz, (std::vector<double>{1, 2, 3, 4, 5, 6, 7, 8, 9}));
  const auto named = read_text(dir, "x,y,z,intensity\r1,2,3,10\r4,5,6,20");
  EXPECT_EQ(named.xyz, (std::vector<double>{1, 2, 3, 4, 5, 6}));
  EXPECT_EQ(column(named, "intensity").values, (std::vector<double>{10, 20}));
  EXPECT_EQ(read_text(dir, "1 2 3\r\n4 5 6\r\n").xyz, (std::vector<double>{1, 2, 3, 4, 5, 6}));
  EXPECT_EQ(vola::io::count_text_columns((dir / "points.txt").string(), 0), 3);
}

// Excel's "CSV UTF-8" begins with a byte order mark: "x" was read as "\xEF\xBB\xBFx",
// and a first number as no number.
TEST(TextLines, AByteOrderMarkIsPassedOver) {
  TempDir dir;
  const auto named = read_text(dir, "\xEF\xBB\xBF" "x,y,z\n1,2,3\n");
  EXPECT_EQ(named.xyz, (std::vector<double>{1, 2, 3}));
  EXPECT_EQ(read_text(dir, "\xEF\xBB\xBF" "1 2 3\n4 5 6\n").xyz, (std::vector<double>{1, 2, 3, 4, 5, 6}));
  EXPECT_EQ(vola::io::count_text_columns((dir / "points.txt").string(), 0), 3);
}

// Leica PTS: each scan begins with its point count on a line of its own.
TEST(TextLines, PtsCountLinesArePassedOver) {
  TempDir dir;
  const auto path = dir / "scan.pts";
  std::ofstream(path, std::ios::binary) << "2\n1.0 2.0 3.0 -1200 255 0 0\n4 5 6 -900 0 255 0\n1\n7 8 9 0 0 0 255\n";
  EXPECT_EQ(vola::io::read_text_points(path.string(), {}).xyz, (std::vector<double>{1, 2, 3, 4, 5, 6, 7, 8, 9}));
  EXPECT_EQ(vola::io::count_text_columns(path.string(), 0), 7);
  // Elsewhere a lone number is a short line, as before.
  EXPECT_THROW(read_text(dir, "2\n1 2 3\n"), vola::FormatError);
}

// Its columns by their count, as PDAL's readers.pts takes them: x y z intensity [r g b].
TEST(TextLines, PtsColumnsAreIntensityAndColour) {
  TempDir dir;
  const auto path = dir / "scan.pts";
  std::ofstream(path, std::ios::binary) << "2\n1.0 2.0 3.0 -1200 255 0 0\n4 5 6 -900 0 255 0\n1\n7 8 9 0 0 0 255\n";
  const auto coloured = vola::io::read_text_points(path.string(), {});
  EXPECT_EQ(names(coloured), (std::vector<std::string>{"intensity", "red", "green", "blue"}));
  EXPECT_EQ(column(coloured, "intensity").values, (std::vector<double>{-1200, -900, 0}));
  EXPECT_EQ(column(coloured, "green").values, (std::vector<double>{0, 255, 0}));
  std::ofstream(path, std::ios::binary) << "1\n1 2 3 17\n";
  EXPECT_EQ(names(vola::io::read_text_points(path.string(), {})), (std::vector<std::string>{"intensity"}));
  std::ofstream(path, std::ios::binary) << "1\n1 2 3 4 5\n";  // no such layout: nothing named
  EXPECT_TRUE(vola::io::read_text_points(path.string(), {}).attributes.empty());
}

// A header of three names and a first point of four (PDAL's test file utm17_3.txt): the
// first point is the odd one, not every line after it.
TEST(TextLines, AFirstPointUnlikeTheHeaderIsTheOneBlamed) {
  TempDir dir;
  try {
    read_text(dir, "X, Y, Z\n\n1.5 , 2.5 , 3.5,27\n4 , 5 , 6\n");
    FAIL() << "read";
  } catch (const vola::FormatError& e) {
    EXPECT_NE(std::string(e.what()).find("line 3: the first point has 4 columns where the header (line 1) names 3 and "
                                         "line 4 has 3"),
              std::string::npos)
        << e.what();
  }
}

// Each name of a header was looked for among the names before it: 80,000 columns took
// seconds. Bounded here at a second for 100,000, far above what a hash set needs.
TEST(TextHeader, ManyColumnsAreNamedInLinearTime) {
  TempDir dir;
  std::string header = "x,y,z", values = "1,2,3";
  for (int c = 0; c < 100000; ++c) header += ",c" + std::to_string(c), values += ",0";
  const auto start = std::chrono::steady_clock::now();
  const auto cloud = read_text(dir, header + "\n" + values + "\n");
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_EQ(cloud.attributes.size(), 100000u);
  EXPECT_LT(seconds, 1.0);
}

// A German spreadsheet's CSV in Windows-1252 names its height "H\xf6he": the raw byte
// became the attribute's name, which JSON reports and Python could not decode. Names
// that are not UTF-8 are read as Latin-1.
TEST(TextHeader, NamesThatAreNotUtf8AreReadAsLatin1) {
  TempDir dir;
  const auto latin1 = read_text(dir, "x;y;z;H\xf6he\n1;2;3;4,5\n");
  EXPECT_EQ(names(latin1), (std::vector<std::string>{"h\xc3\xb6he"}));
  EXPECT_EQ(column(latin1, "h\xc3\xb6he").values, (std::vector<double>{4.5}));
  const auto utf8 = read_text(dir, "x;y;z;H\xc3\xb6he\n1;2;3;4,5\n");  // already UTF-8: kept
  EXPECT_EQ(names(utf8), (std::vector<std::string>{"h\xc3\xb6he"}));
}
