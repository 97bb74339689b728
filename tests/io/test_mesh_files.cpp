// vola's own OFF and STL readers and polygon triangulation, on the variants other tools
// write that Assimp read wrong or refused (src/io/mesh_files.hpp), and on broken files.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include "mesh_files.hpp"
#include "polygon_triangles.hpp"
#include "test_support.hpp"
#include "vola/error.hpp"
#include "vola/io/ply.hpp"

namespace {

using vola::Point;
using vola::io::Triangle;

std::span<const std::uint8_t> bytes_of(const std::string& text) {
  return {reinterpret_cast<const std::uint8_t*>(text.data()), text.size()};
}

double area(const Triangle& t) {
  const double u[3] = {t[1][0] - t[0][0], t[1][1] - t[0][1], t[1][2] - t[0][2]};
  const double v[3] = {t[2][0] - t[0][0], t[2][1] - t[0][1], t[2][2] - t[0][2]};
  const double c[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
  return 0.5 * std::sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
}

// The cause of the FormatError that `f` throws ("" when none).
template <class F>
std::string cause_of(F&& f) {
  const auto error = vola_test::format_error_of(std::forward<F>(f));
  return error ? error->cause() : std::string();
}

// A box of six quads, with comment lines where CGAL's verbose OFF writer puts them.
std::string box_off(bool comments) {
  std::string off = "OFF\n8 6 0\n";
  if (comments) off += "# 8 vertices\n# ------------------------------------------\n\n";
  for (int v = 0; v < 8; ++v)
    off += std::to_string(v & 1) + " " + std::to_string((v >> 1) & 1) + " " + std::to_string((v >> 2) & 1) + "\n";
  if (comments) off += "\n# 6 facets\n# ------------------------------------------\n\n";
  off += "4 0 2 3 1\n4 4 5 7 6\n4 0 1 5 4\n4 2 6 7 3\n4 0 4 6 2\n4 1 3 7 5\n";
  if (comments) off += "\n\n# End of OFF #\n";
  return off;
}

double total_area(const std::vector<Triangle>& triangles) {
  double sum = 0.0;
  for (const Triangle& t : triangles) sum += area(t);
  return sum;
}

TEST(OffReader, CommentLinesAmongTheFacesAreComments) {
  const auto plain = vola::io::parse_off(bytes_of(box_off(false)), "box.off");
  const auto commented = vola::io::parse_off(bytes_of(box_off(true)), "cgal.off");
  ASSERT_EQ(plain.size(), 12u);  // Assimp read 8 from the commented file: a face lost per comment line
  ASSERT_EQ(commented.size(), 12u);
  EXPECT_EQ(plain, commented);
  EXPECT_DOUBLE_EQ(total_area(commented), 6.0);
}

TEST(OffReader, HeaderForms) {
  // ModelNet's keyword glued to the counts, counts on the next line, no keyword, a
  // colour after the corners, 4OFF's homogeneous w, CRLF, a byte order mark.
  const std::string tri = "0 0 0\n2 0 0\n0 2 0\n3 0 1 2\n";
  for (const std::string& text :
       std::vector<std::string>{"OFF3 1 0\n" + tri, "OFF\n3 1\n" + tri, "3 1 0\n" + tri, "COFF\n3 1 0\n" + tri,
                                "OFF\r\n3 1 0\r\n0 0 0\r\n2 0 0\r\n0 2 0\r\n3 0 1 2 255 0 0\r\n",
                                "\xef\xbb\xbfOFF 3 1 0\n" + tri, "4OFF\n3 1 0\n0 0 0 2\n4 0 0 2\n0 4 0 2\n3 0 1 2\n"}) {
    SCOPED_TRACE(text);
    const auto t = vola::io::parse_off(bytes_of(text), "t.off");
    ASSERT_EQ(t.size(), 1u);
    EXPECT_EQ(t[0], (Triangle{Point{0, 0, 0}, Point{2, 0, 0}, Point{0, 2, 0}}));
  }
}

TEST(OffReader, BrokenFilesAreRefusedNamingTheLine) {
  const std::string head = "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n";
  const std::pair<std::string, std::string> broken[] = {
      {head + "3 0 1 7\n", "line 6: face 0 refers to vertex 7 of 3"},  // Assimp clamped it to the last vertex
      {head + "3 0 1 -2\n", "line 6: face 0: '-2' is not a vertex index"},
      {head + "1000000000 0 1 2\n", "line 6: face 0 declares 1000000000 corners, its line holds fewer"},
      {head + "3 0\n", "line 6: face 0 declares 3 corners and lists 1"},
      {head + "0\n", "line 6: face 0 starts with '0', not a corner count of 1 or more"},
      {head, "the header declares 1 faces, the file ends after 0"},
      // Three vertex lines under a count of 2: the third reads as a face (one corner, a colour), the face line is one
      // too many.
      {"OFF\n2 1 0\n0 0 0\n1 0 0\n1 1 0\n3 0 1 1\n", "line 6: more lines than the header's 2 vertices and 1 faces"},
      {"OFF\n3 1 0\n0 0 0\n1 0\n0 1 0\n3 0 1 2\n", "line 4: vertex 1 has fewer than 3 coordinates"},
      {"OFF BINARY\n3 1 0\n", "line 1: a binary OFF file"},
      {"nOFF 4 3 1 0\n", "line 1: an nOFF file of dimension 4"},
  };
  for (const auto& [text, expected] : broken) {
    SCOPED_TRACE(text);
    EXPECT_NE(cause_of([&] { vola::io::parse_off(bytes_of(text), "broken.off"); }).find(expected), std::string::npos)
        << cause_of([&] { vola::io::parse_off(bytes_of(text), "broken.off"); });
  }
}

// An L-shaped hexagon whose first corner is on the inner arm: its fan crosses the notch
// [1, 2] x [1, 2]; its ears stay inside the L.
const std::vector<Point> kL = {{1, 1, 0}, {1, 2, 0}, {0, 2, 0}, {0, 0, 0}, {2, 0, 0}, {2, 1, 0}};

void expect_covers_the_l(const std::vector<Triangle>& triangles) {
  ASSERT_EQ(triangles.size(), 4u);
  EXPECT_NEAR(total_area(triangles), 3.0, 1e-12);  // a fan covers 3 too, but overlapping, and the notch
  for (const Triangle& t : triangles) {
    const double cx = (t[0][0] + t[1][0] + t[2][0]) / 3, cy = (t[0][1] + t[1][1] + t[2][1]) / 3;
    EXPECT_FALSE(cx > 1 && cy > 1) << "a triangle in the notch";
  }
}

TEST(PolygonTriangles, AConcaveFaceIsCutByItsEarsInEveryReader) {
  std::string off = "OFF\n6 1 0\n";
  for (const Point& p : kL)
    off += std::to_string(p[0]) + " " + std::to_string(p[1]) + " " + std::to_string(p[2]) + "\n";
  off += "6 0 1 2 3 4 5\n";
  expect_covers_the_l(vola::io::parse_off(bytes_of(off), "l.off"));
  const std::string ply =
      "ply\nformat ascii 1.0\nelement face 1\nproperty list uchar int vertex_indices\nelement vertex 6\n"
      "property float x\nproperty float y\nproperty float z\nend_header\n6 0 1 2 3 4 5\n" +
      off.substr(off.find("1.0"), off.rfind("6 0 1") - off.find("1.0"));
  expect_covers_the_l(vola::io::parse_ply(bytes_of(ply), "l.ply").triangles);
  std::string stl = "solid l\nfacet normal 0 0 1\nouter loop\n";
  for (const Point& p : kL) stl += "vertex " + std::to_string(p[0]) + " " + std::to_string(p[1]) + " 0\n";
  stl += "endloop\nendfacet\nendsolid l\n";
  expect_covers_the_l(vola::io::parse_stl(bytes_of(stl), "l.stl"));
}

// Random star-shaped polygons, in random planes and windings: the triangles' areas add
// up to the polygon's (so they neither overlap nor leave a gap), n - 2 of them.
TEST(PolygonTriangles, EarsCoverRandomPolygonsExactly) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> radius(0.2, 1.0), unit(-1.0, 1.0);
  for (int trial = 0; trial < 300; ++trial) {
    const std::size_t n = 3 + rng() % 40;
    // Angles in order around the centre (gaps below pi keep the polygon simple); a
    // random radius each makes it concave.
    std::vector<double> angle(n);
    for (std::size_t k = 0; k < n; ++k)
      angle[k] = (static_cast<double>(k) + 0.45 * unit(rng)) * 2 * M_PI / static_cast<double>(n);
    double u[3] = {unit(rng), unit(rng), unit(rng)}, w[3] = {unit(rng), unit(rng), unit(rng)};
    double plane_area = 0.0;  // of the 2D polygon, by the shoelace formula
    std::vector<std::array<double, 2>> flat(n);
    for (std::size_t k = 0; k < n; ++k) {
      const double r = radius(rng);
      flat[k] = {r * std::cos(angle[k]), r * std::sin(angle[k])};
    }
    if (trial % 2) std::reverse(flat.begin(), flat.end());
    for (std::size_t k = 0; k < n; ++k)
      plane_area += flat[k][0] * flat[(k + 1) % n][1] - flat[(k + 1) % n][0] * flat[k][1];
    plane_area = std::fabs(plane_area) / 2;
    // Into 3D through two axes u, w: areas scale by |u x w| when u and w are made orthonormal.
    const double nu = std::sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
    for (double& x : u) x /= nu;
    const double d = u[0] * w[0] + u[1] * w[1] + u[2] * w[2];
    for (int a = 0; a < 3; ++a) w[a] -= d * u[a];
    const double nw = std::sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
    for (double& x : w) x /= nw;
    std::vector<Point> corners(n);
    for (std::size_t k = 0; k < n; ++k)
      for (int a = 0; a < 3; ++a) corners[k][a] = 5.0 + flat[k][0] * u[a] + flat[k][1] * w[a];
    std::vector<std::array<std::uint32_t, 3>> cut;
    vola::io::triangulate_polygon(corners, cut);
    ASSERT_EQ(cut.size(), n - 2) << "trial " << trial;
    double sum = 0.0;
    for (const auto& t : cut) sum += area({corners[t[0]], corners[t[1]], corners[t[2]]});
    EXPECT_NEAR(sum, plane_area, 1e-9 * (1 + plane_area)) << "trial " << trial << ", " << n << " corners";
  }
}

std::string binary_stl(const std::string& header, std::uint32_t declared, std::size_t triangles, std::size_t trailing) {
  std::string b(84, '\0');
  std::memcpy(b.data(), header.data(), std::min<std::size_t>(header.size(), 80));
  std::memcpy(b.data() + 80, &declared, 4);
  for (std::size_t t = 0; t < triangles; ++t) {
    std::string r(50, '\0');
    const float corners[9] = {0, 0, 0, 1, 0, 0, 0, 1, static_cast<float>(t)};
    std::memcpy(r.data() + 12, corners, sizeof corners);
    b += r;
  }
  return b + std::string(trailing, 'x');
}

TEST(StlReader, UpperCaseAsciiAndInexactBinaryFilesAreRead) {
  const std::string facet =
      " facet normal 0 0 1\n  outer loop\n   vertex 0 0 0\n   vertex 1 0 0\n   vertex 0 1 0\n"
      "  endloop\n endfacet\n";
  std::string upper = "SOLID DEFORM-3D STL FILE\n" + facet + "ENDSOLID\n";
  for (std::size_t k = 0; k < upper.size(); ++k) upper[k] = static_cast<char>(std::toupper(upper[k]));
  for (const std::string& text :
       std::vector<std::string>{upper, "Solid Unity Mesh\n" + facet + "endsolid Unity Mesh\n", "solid\n" + facet}) {
    SCOPED_TRACE(text);
    const auto t = vola::io::parse_stl(bytes_of(text), "ascii.stl");
    ASSERT_EQ(t.size(), 1u);
    EXPECT_EQ(t[0], (Triangle{Point{0, 0, 0}, Point{1, 0, 0}, Point{0, 1, 0}}));
  }
  // Binary: exact, bytes after the triangles, a count left 0, a "solid" header with bytes after.
  for (const auto& [file, expected] :
       {std::pair{binary_stl("binary", 3, 3, 0), 3u}, std::pair{binary_stl("binary", 3, 3, 2), 3u},
        std::pair{binary_stl("binary", 0, 4, 0), 4u}, std::pair{binary_stl("solid part", 2, 2, 7), 2u}}) {
    const auto t = vola::io::parse_stl(bytes_of(file), "binary.stl");
    ASSERT_EQ(t.size(), expected);
    EXPECT_EQ(t.back()[2], (Point{0, 1, static_cast<double>(expected - 1)}));
  }
}

TEST(StlReader, BrokenFilesAreRefusedNamingTheLine) {
  const std::string cut_short = "solid a\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\n";
  EXPECT_NE(
      cause_of([&] { vola::io::parse_stl(bytes_of(cut_short), "cut.stl"); }).find("the facet of line 2 is cut short"),
      std::string::npos);
  EXPECT_NE(cause_of([&] {
              vola::io::parse_stl(bytes_of("solid a\nfacet normal 0 0 1\nouter loop\nvertex 0 x 0\n"), "x.stl");
            }).find("line 4: 'x' is not a number"),
            std::string::npos);
  EXPECT_NE(cause_of([&] {
              vola::io::parse_stl(bytes_of(binary_stl("binary", 9, 3, 0)), "short.stl");
            }).find("declares 9 triangles (534 bytes), the file has 234"),
            std::string::npos);
  EXPECT_NE(cause_of([&] {
              vola::io::parse_stl(bytes_of("solid empty\nendsolid empty\n"), "empty.stl");
            }).find("no triangles"),
            std::string::npos);
  EXPECT_FALSE(cause_of([&] { vola::io::parse_stl(bytes_of("abc"), "tiny.stl"); }).empty());
}

}  // namespace
