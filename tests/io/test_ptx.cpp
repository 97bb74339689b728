// Leica PTX scans written here: the matrix applied as a row vector times it (a quarter
// turn about z tells that from the column convention), points of no return left out,
// colours and intensity kept, a second scan of its own matrix, and malformed files
// refused naming the line.
#include <gtest/gtest.h>

#include <fstream>
#include <string>

#include "test_support.hpp"
#include "vola/error.hpp"
#include "vola/io/input.hpp"

namespace {

namespace fs = std::filesystem;

// A scan header: columns, rows, the scanner's position and axes, then the matrix rows.
std::string header(int columns, int rows, const std::string& matrix) {
  return std::to_string(columns) + "\n" + std::to_string(rows) + "\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n" + matrix;
}

// A quarter turn about z ([x y z 1] M: x goes to y, y to -x), then a move by (10, 20, 30).
const std::string kTurn = "0 1 0 0\n-1 0 0 0\n0 0 1 0\n10 20 30 1\n";
const std::string kIdentity = "1 0 0 0\n0 1 0 0\n0 0 1 0\n0 0 0 1\n";

vola::io::Input read(const fs::path& path, const std::string& text, vola::io::InputOptions options = {}) {
  std::ofstream(path, std::ios::binary) << text;
  return vola::io::read_input(path.string(), "auto", options);
}

std::string error_of(const fs::path& path, const std::string& text) {
  try {
    read(path, text);
  } catch (const vola::Error& e) {
    return e.what();
  }
  return "";
}

TEST(Ptx, ScansAreMovedByTheirMatrixAsRowVectors) {
  vola_test::TempDir dir;
  const fs::path path = dir / "scan.ptx";
  const std::string text = header(2, 2, kTurn) + "1 0 0 0.5 255 0 0\r\n0 0 0 0.5 0 0 0\r\n0 2 0.5 0.25 0 255 0\r\n" +
                           "0 0 0 0\r\n\n" + header(1, 1, kIdentity) + "7 8 9 1 1 2 3\n";
  const vola::io::Input in = read(path, text);
  EXPECT_EQ(in.format, "ptx");
  EXPECT_EQ(in.cloud.xyz, (std::vector<double>{10, 21, 30, 8, 20, 30.5, 7, 8, 9}));
  EXPECT_EQ(in.not_finite, 2u);  // the two points of no return
  ASSERT_EQ(in.cloud.attributes.size(), 4u);
  EXPECT_EQ(in.cloud.attributes[0].name, "intensity");
  EXPECT_EQ(in.cloud.attributes[0].values, (std::vector<double>{0.5, 0.25, 1}));
  EXPECT_EQ(in.cloud.attributes[1].name, "red");
  EXPECT_EQ(in.cloud.attributes[1].values, (std::vector<double>{255, 0, 1}));
  EXPECT_EQ(in.cloud.attributes[2].values, (std::vector<double>{0, 255, 2}));
  vola::io::InputOptions payload;
  payload.payload = true;
  payload.attributes = false;
  const vola::io::Input p = read(path, text, payload);
  EXPECT_TRUE(p.cloud.attributes.empty());
  EXPECT_EQ(p.cloud.payload, (std::vector<std::uint64_t>{255, 255u << 8, 1u | 2u << 8 | 3u << 16}));
}

TEST(Ptx, MalformedFilesAreRefusedNamingTheLine) {
  vola_test::TempDir dir;
  const fs::path path = dir / "bad.ptx";
  const auto expect = [&](const std::string& text, const std::string& message) {
    const std::string error = error_of(path, text);
    EXPECT_NE(error.find(message), std::string::npos) << error;
    EXPECT_NE(error.find("bad.ptx"), std::string::npos) << error;
  };
  expect(header(2, 2, kIdentity) + "1 2 3 0.5\n4 5 6 0.5\n", "line 12: the file ends after 2 of the scan's 4 points");
  expect(header(1, 1, kIdentity) + "1 2 3\n", "line 11: a point line holds x y z intensity [red green blue]");
  expect(header(2, 1, kIdentity) + "1 2 3 0.5\n1 2 3 0.5 1 2 3\n",
         "line 12: 7 values where the file's point lines hold 4");
  expect("2.5\n1\n", "line 1: a scan's number of columns must be one whole number");
  expect("1E57\n1\n", "line 1: a scan's number of columns must be one whole number");  // (a fuzz finding)
  expect("1\n-3\n", "line 2: a scan's number of rows must be one whole number");
  expect(header(1, 1, "1 0 0 0\n0 1 0\n"), "line 8: a scan header's lines 7-10 hold four numbers each");
  expect(header(1, 1, kIdentity) + "1 2 x 0.5\n", "line 11: 'x 0.5' is not a number");
  // A projective matrix (or damage) was used without its last column.
  expect(header(1, 1, "1 0 0 5\n0 1 0 0\n0 0 1 0\n0 0 0 2\n") + "1 2 3 0.5\n",
         "line 10: the transformation matrix's last column is not 0 0 0 1 (row 1 ends in 5");
}

TEST(Ptx, AShortMissFirstDoesNotSetTheLinesWidth) {
  // A coloured scan whose first point is a miss written with 4 values was refused ("7
  // values where the file's point lines hold 4"); the same miss second was read.
  vola_test::TempDir dir;
  const fs::path path = dir / "first.ptx";
  const vola::io::Input in = read(path, header(3, 1, kIdentity) + "0 0 0 0.5\n1 2 3 0.5 10 20 30\n0 0 0 0.5\n");
  EXPECT_EQ(in.cloud.xyz, (std::vector<double>{1, 2, 3}));
  EXPECT_EQ(in.not_finite, 2u);
  ASSERT_EQ(in.cloud.attributes.size(), 4u);
  EXPECT_EQ(in.cloud.attributes[1].values, (std::vector<double>{10}));
}

}  // namespace
