// PLY export: centres and cube surfaces, checked by an independent parser written here
// from the PLY description (and through the project's PLY reader when this build has
// one): points -> vol -> PLY -> points -> vol keeps the voxel set, attribute values
// survive, and the cube mesh is exactly the voxels' outer surface, outward facing.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>
#include <sstream>

#include "export_test_support.hpp"
#include "vola/io/export.hpp"
#include "vola/io/input.hpp"
#include "vola/io/ply.hpp"

namespace {

using namespace vola_export_test;
using vola_test::TempDir;
using vola_test::Xyz;
using vola_test::XyzSet;

// ---- A small PLY parser: header, then ascii or binary little-endian rows ----

struct PlyProperty {
  std::string name, type;
  bool list = false;
  std::string count_type;
};
struct PlyElement {
  std::string name;
  std::uint64_t count = 0;
  std::vector<PlyProperty> properties;
  std::vector<std::vector<double>> rows;              // scalar properties, in order
  std::vector<std::vector<std::uint32_t>> list_rows;  // the list property, if any
  int index_of(const std::string& property) const {
    int scalar = 0;
    for (const auto& p : properties) {
      if (p.list) continue;
      if (p.name == property) return scalar;
      ++scalar;
    }
    return -1;
  }
  std::string type_of(const std::string& property) const {
    for (const auto& p : properties)
      if (p.name == property) return p.type;
    return {};
  }
};
struct PlyFile {
  std::string format;
  std::vector<PlyElement> elements;
  const PlyElement& element(const std::string& name) const {
    for (const auto& e : elements)
      if (e.name == name) return e;
    throw std::runtime_error("no element " + name);
  }
};

std::size_t type_size(const std::string& t) {
  if (t == "char" || t == "uchar") return 1;
  if (t == "short" || t == "ushort") return 2;
  if (t == "int" || t == "uint" || t == "float") return 4;
  if (t == "double") return 8;
  throw std::runtime_error("unknown PLY type " + t);
}

double binary_value(const std::uint8_t* p, const std::string& t) {
  auto load = [p](auto v) {
    std::memcpy(&v, p, sizeof v);
    return static_cast<double>(v);
  };
  if (t == "char") return load(std::int8_t{});
  if (t == "uchar") return load(std::uint8_t{});
  if (t == "short") return load(std::int16_t{});
  if (t == "ushort") return load(std::uint16_t{});
  if (t == "int") return load(std::int32_t{});
  if (t == "uint") return load(std::uint32_t{});
  if (t == "float") return load(float{});
  return load(double{});
}

PlyFile parse_ply(const std::vector<std::uint8_t>& bytes) {
  PlyFile ply;
  std::size_t at = 0;
  auto next_line = [&] {
    const auto end = std::find(bytes.begin() + static_cast<std::ptrdiff_t>(at), bytes.end(), '\n');
    if (end == bytes.end()) throw std::runtime_error("header has no end_header");
    std::string line(bytes.begin() + static_cast<std::ptrdiff_t>(at), end);
    at = static_cast<std::size_t>(end - bytes.begin()) + 1;
    return line;
  };
  if (next_line() != "ply") throw std::runtime_error("no ply magic");
  for (std::string line = next_line(); line != "end_header"; line = next_line()) {
    std::istringstream s(line);
    std::string word;
    s >> word;
    if (word == "format") s >> ply.format;
    else if (word == "element") {
      PlyElement e;
      s >> e.name >> e.count;
      ply.elements.push_back(e);
    } else if (word == "property") {
      PlyProperty p;
      s >> p.type;
      if (p.type == "list") {
        p.list = true;
        s >> p.count_type >> p.type;
      }
      s >> p.name;
      ply.elements.back().properties.push_back(p);
    } else if (word != "comment") {
      throw std::runtime_error("unexpected header line: " + line);
    }
  }
  const bool ascii = ply.format == "ascii";
  auto take = [&](const std::string& type) {  // the next binary value, bounds-checked
    const std::size_t size = type_size(type);
    if (at + size > bytes.size()) throw std::runtime_error("binary data ends early");
    const double v = binary_value(bytes.data() + at, type);
    at += size;
    return v;
  };
  std::istringstream text(ascii ? std::string(bytes.begin() + static_cast<std::ptrdiff_t>(at), bytes.end()) : "");
  for (auto& e : ply.elements) {
    for (std::uint64_t r = 0; r < e.count; ++r) {
      std::vector<double> row;
      std::vector<std::uint32_t> list;
      for (const auto& p : e.properties) {
        if (p.list) {
          double n = 0;
          if (ascii) text >> n;
          else n = take(p.count_type);
          for (int i = 0; i < static_cast<int>(n); ++i) {
            double v = 0;
            if (ascii) text >> v;
            else v = take(p.type);
            list.push_back(static_cast<std::uint32_t>(v));
          }
        } else {
          double v = 0;
          if (ascii) {
            std::string token;
            if (!(text >> token)) throw std::runtime_error("ascii data ends early");
            // A float's text reads back exactly as a float, not necessarily as a double.
            v = p.type == "float" ? static_cast<double>(std::stof(token)) : std::stod(token);
          } else {
            v = take(p.type);
          }
          row.push_back(v);
        }
      }
      e.rows.push_back(std::move(row));
      e.list_rows.push_back(std::move(list));
    }
  }
  if (ascii) {
    std::string rest;
    if (text >> rest) throw std::runtime_error("data after the last element: " + rest);
  } else if (at != bytes.size()) {
    throw std::runtime_error("binary data has " + std::to_string(bytes.size() - at) + " bytes after the last element");
  }
  return ply;
}

PlyFile export_and_parse(const vola::Tree& tree, const vola::io::PlyOptions& options,
                         vola::io::PlyReport* report = nullptr) {
  TempDir dir;
  const auto file = dir / "out.ply";
  const auto r = vola::io::write_ply(tree, file.string(), options);
  if (report) *report = r;
  return parse_ply(vola_test::read_bytes(file));
}

vola::PointCloud vertex_points(const PlyFile& ply) {
  const PlyElement& v = ply.element("vertex");
  vola::PointCloud cloud;
  const int ix = v.index_of("x"), iy = v.index_of("y"), iz = v.index_of("z");
  for (const auto& row : v.rows) {
    cloud.xyz.push_back(row[ix]);
    cloud.xyz.push_back(row[iy]);
    cloud.xyz.push_back(row[iz]);
  }
  return cloud;
}

// The value a PLY property should hold for a column: the column's own (16-bit colours
// stay 16-bit; 8-bit colours in 16-bit columns become uchar with the same value).
double expected_ply_value(const vola::AttributeColumn& column, std::size_t rank) { return column.get(rank); }

// Does any colour column use the 16-bit range (then colours are written as ushort)?
bool wide_colours(const vola::Tree& tree) {
  for (const char* name : {"red", "green", "blue"})
    if (const auto* c = tree.attributes().find(name))
      for (std::size_t r = 0; r < c->size(); ++r)
        if (c->type() == vola::ValueType::u16 && c->get(r) > 255) return true;
  return false;
}

// ---- Centres ----

class PlyCentres : public ::testing::TestWithParam<int> {};

TEST_P(PlyCentres, RoundTripKeepsVoxelsAndAttributes) {
  const int depth = GetParam();
  for (std::uint64_t seed = 0; seed < 6; ++seed) {
    const Sample s = random_sample(1000 * depth + seed, depth, true);
    SCOPED_TRACE(s.describe);
    for (bool ascii : {false, true}) {
      SCOPED_TRACE(ascii ? "ascii" : "binary");
      const PlyFile ply = export_and_parse(s.tree, {.ascii = ascii});
      EXPECT_EQ(ply.format, ascii ? "ascii" : "binary_little_endian");
      const PlyElement& vertex = ply.element("vertex");
      ASSERT_EQ(vertex.count, s.tree.voxel_count());
      EXPECT_EQ(vola_test::voxel_set(build_on(vertex_points(ply), s.grid)), s.voxels);
      // Vertex i is the voxel of rank i: its centre and its attribute row.
      const auto sequence = vola_test::voxel_sequence(s.tree);
      const vola::Quantizer q = s.tree.quantizer();
      for (std::size_t i = 0; i < sequence.size(); ++i) {
        const vola::Point c = q.center(vola_test::to_voxel(sequence[i]));
        for (int a = 0; a < 3; ++a) ASSERT_EQ(vertex.rows[i][a], c[a]);
        for (const auto& column : s.tree.attributes().columns())
          ASSERT_EQ(vertex.rows[i][vertex.index_of(column.name())], expected_ply_value(column, i))
              << column.name() << " at rank " << i;
      }
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Depths, PlyCentres, ::testing::Range(1, 7));

TEST(PlyCentres, PropertyTypesFollowTheColumns) {
  const Sample s = random_sample(7, 3, true);
  const PlyFile ply = export_and_parse(s.tree, {});
  const PlyElement& vertex = ply.element("vertex");
  EXPECT_EQ(vertex.type_of("x"), "double");
  // 16-bit colours stay ushort (cutting them to 8 bits lost what readers keep); 8-bit ones uchar.
  EXPECT_EQ(vertex.type_of("red"), wide_colours(s.tree) ? "ushort" : "uchar");
  EXPECT_EQ(vertex.type_of("intensity"), "ushort");
  EXPECT_EQ(vertex.type_of("classification"), "uchar");
  EXPECT_EQ(vertex.type_of("reflectance"), "float");
  EXPECT_EQ(vertex.type_of("temperature"), "short");
  EXPECT_EQ(vertex.type_of("pulse"), "uint");
}

TEST(PlyCentres, EightBitColoursInSixteenBitColumnsStayAsTheyAre) {
  // Many LAS files store 0..255 colours in their 16-bit fields: / 256 would make them black.
  vola::Tree tree = vola::build_from_voxels(std::vector<vola::Voxel>{{0, 0, 0}, {1, 2, 3}}, 1);
  for (const char* name : {"red", "green", "blue"}) {
    vola::AttributeColumn c(name, vola::ValueType::u16, vola::Reduction::mean, 2);
    c.set(0, 17);
    c.set(1, 255);
    tree.attributes().add(std::move(c));
  }
  const PlyFile ply = export_and_parse(tree, {});
  const PlyElement& vertex = ply.element("vertex");
  for (const char* name : {"red", "green", "blue"}) {
    EXPECT_EQ(vertex.rows[0][vertex.index_of(name)], 17);
    EXPECT_EQ(vertex.rows[1][vertex.index_of(name)], 255);
  }
}

// 16-bit colours keep every bit through PLY and back (they were cut to 8: 60000 -> 234,
// 255 -> 0), and vola's PLY reader reads them back as the same 16-bit values.
TEST(PlyCentres, SixteenBitColoursRoundTrip) {
  vola::Tree tree = vola::build_from_voxels(std::vector<vola::Voxel>{{0, 0, 0}, {1, 2, 3}}, 1);
  for (const char* name : {"red", "green", "blue"}) {
    vola::AttributeColumn c(name, vola::ValueType::u16, vola::Reduction::mean, 2);
    c.set(0, 60000);
    c.set(1, 255);
    tree.attributes().add(std::move(c));
  }
  const PlyFile ply = export_and_parse(tree, {});
  const PlyElement& vertex = ply.element("vertex");
  const vola_test::TempDir dir;
  const std::string path = (dir.path() / "colours.ply").string();
  vola::io::write_ply(tree, path, {});
  const vola::io::Input back = vola::io::read_ply(path);
  for (const char* name : {"red", "green", "blue"}) {
    EXPECT_EQ(vertex.type_of(name), "ushort");
    EXPECT_EQ(vertex.rows[0][vertex.index_of(name)], 60000);
    EXPECT_EQ(vertex.rows[1][vertex.index_of(name)], 255);
  }
  ASSERT_GE(back.cloud.attributes.size(), 3u);
  EXPECT_EQ(back.cloud.attributes[0].name, "red");
  EXPECT_EQ(back.cloud.attributes[0].values, (std::vector<double>{60000, 255}));
}

TEST(PlyCentres, SixtyFourBitAndOddlyNamedColumns) {
  vola::Tree tree = vola::build_from_voxels(std::vector<vola::Voxel>{{3, 0, 1}}, 1);
  tree.set_frame({vola::Quantization::grid, {0, 0, 0}, 1.0});
  vola::AttributeColumn big("big count", vola::ValueType::u64, vola::Reduction::max, 1);
  big.set(0, 123456789012.0);
  tree.attributes().add(std::move(big));
  vola::AttributeColumn x("x", vola::ValueType::i8, vola::Reduction::min, 1);
  x.set(0, -5);
  tree.attributes().add(std::move(x));
  for (bool ascii : {false, true}) {
    const PlyFile ply = export_and_parse(tree, {.ascii = ascii});
  const PlyElement& vertex = ply.element("vertex");
    EXPECT_EQ(vertex.type_of("big_count"), "double");  // PLY has no 64-bit integers
    EXPECT_EQ(vertex.rows[0][vertex.index_of("big_count")], 123456789012.0);
    EXPECT_EQ(vertex.type_of("x_2"), "char");  // "x" is the coordinate
    EXPECT_EQ(vertex.rows[0][vertex.index_of("x_2")], -5);
    EXPECT_EQ(vertex.rows[0][vertex.index_of("x")], 3.5);
  }
}

TEST(PlyCentres, EmptyTree) {
  const PlyFile ply = export_and_parse(vola::Tree(), {});
  EXPECT_EQ(ply.element("vertex").count, 0u);
}

TEST(PlyCentres, ThroughTheProjectsPlyReaderWhenBuilt) {
  const auto& formats = vola::io::input_formats();
  const bool has_ply = std::any_of(formats.begin(), formats.end(), [](const auto& f) { return f.name == "ply"; });
  if (!has_ply) GTEST_SKIP() << "this build has no PLY reader (the test parser above covers the writer)";
  for (int depth = 1; depth <= 6; ++depth) {
    const Sample s = random_sample(77 + depth, depth, true);
    SCOPED_TRACE(s.describe);
    for (bool ascii : {false, true}) {
      TempDir dir;
      const auto file = dir / "out.ply";
      vola::io::write_ply(s.tree, file.string(), {.ascii = ascii});
      const vola::io::Input in = vola::io::read_input(file.string(), "auto", {});
      EXPECT_EQ(vola_test::voxel_set(rebuild(in, s.grid)), s.voxels);
    }
  }
}

// ---- Cubes ----

struct MeshCounts {
  std::uint64_t vertices, faces;
};

MeshCounts cube_counts(const std::vector<vola::Voxel>& voxels, int depth) {
  const vola::Tree tree = vola::build_from_voxels(voxels, depth);
  vola::io::PlyReport report;
  const PlyFile ply = export_and_parse(tree, {.cubes = true}, &report);
  EXPECT_EQ(ply.element("vertex").count, report.vertices);
  EXPECT_EQ(ply.element("face").count, report.faces);
  return {report.vertices, report.faces};
}

TEST(PlyCubes, CountsOfSmallShapes) {
  auto check = [](const std::vector<vola::Voxel>& voxels, std::uint64_t vertices, std::uint64_t faces) {
    const MeshCounts c = cube_counts(voxels, 2);
    EXPECT_EQ(c.vertices, vertices);
    EXPECT_EQ(c.faces, faces);
  };
  check({{5, 5, 5}}, 8, 6);                        // one cube: 6 quads (12 triangles)
  check({{5, 5, 5}, {6, 5, 5}}, 12, 10);           // sharing a face: it goes, its 4 corners are shared
  check({{5, 5, 5}, {6, 6, 5}}, 14, 12);           // sharing an edge: 2 corners shared, no face removed
  check({{5, 5, 5}, {6, 6, 6}}, 15, 12);           // sharing a corner
  check({{0, 0, 0}, {15, 15, 15}}, 16, 12);        // at the grid's borders
  std::vector<vola::Voxel> block;                  // 2x2x2: a cube of side 2
  for (std::uint32_t i = 0; i < 8; ++i) block.push_back({4 + (i & 1), 4 + ((i >> 1) & 1), 4 + (i >> 2)});
  check(block, 26, 24);
  std::vector<vola::Voxel> full;  // the whole depth-1 grid: 4x4 quads per side
  for (std::uint32_t i = 0; i < 64; ++i) full.push_back({i & 3, (i >> 2) & 3, i >> 4});
  const MeshCounts c = cube_counts(full, 1);
  EXPECT_EQ(c.faces, 96u);
  EXPECT_EQ(c.vertices, 5u * 5 * 5 - 3 * 3 * 3);
}

// Slow reference: faces = voxel sides whose neighbour is not in the set.
std::uint64_t slow_surface_faces(const XyzSet& voxels) {
  std::uint64_t faces = 0;
  for (const auto& v : voxels)
    for (int a = 0; a < 3; ++a)
      for (int d : {-1, 1}) {
        Xyz n = v;
        n[a] = static_cast<std::uint32_t>(static_cast<std::int64_t>(n[a]) + d);  // wraps below 0: never in the set
        if (!voxels.count(n)) ++faces;
      }
  return faces;
}

class PlyCubesRandom : public ::testing::TestWithParam<int> {};

TEST_P(PlyCubesRandom, SurfaceIsExactClosedAndOutward) {
  const int depth = GetParam();
  for (std::uint64_t seed = 0; seed < 4; ++seed) {
    const Sample s = random_sample(500 + 10 * depth + seed, depth, true);
    SCOPED_TRACE(s.describe);
    for (bool ascii : {false, true}) {
      const PlyFile ply = export_and_parse(s.tree, {.ascii = ascii, .cubes = true});
      const PlyElement& vertex = ply.element("vertex");
      const PlyElement& face = ply.element("face");
      ASSERT_EQ(face.count, slow_surface_faces(s.voxels));
      // Corners in grid units (exact: origin + integer * voxel size, divided back).
      const double vs = s.grid.voxel_size;
      std::vector<std::array<double, 3>> corner(vertex.count);
      for (std::size_t i = 0; i < vertex.count; ++i)
        for (int a = 0; a < 3; ++a) corner[i][a] = std::round((vertex.rows[i][a] - s.grid.origin[a]) / vs);
      std::vector<bool> used(vertex.count, false);
      std::int64_t six_volume = 0;
      std::map<std::pair<std::uint32_t, std::uint32_t>, int> edges;
      for (std::size_t f = 0; f < face.count; ++f) {
        const auto& q = face.list_rows[f];
        ASSERT_EQ(q.size(), 4u);
        for (auto i : q) {
          ASSERT_LT(i, vertex.count);
          used[i] = true;
        }
        // A unit square of the lattice...
        for (int k = 0; k < 4; ++k) {
          const auto& p = corner[q[k]];
          const auto& n = corner[q[(k + 1) % 4]];
          double step = 0;
          for (int a = 0; a < 3; ++a) step += std::abs(n[a] - p[a]);
          ASSERT_EQ(step, 1.0);
          ++edges[{std::min(q[k], q[(k + 1) % 4]), std::max(q[k], q[(k + 1) % 4])}];
        }
        // ...whose signed volume contribution (divergence theorem) adds up to the voxels'.
        auto triple = [&](std::uint32_t a, std::uint32_t b, std::uint32_t c) {
          std::int64_t p[3], r[3], t[3];
          for (int k = 0; k < 3; ++k) {
            p[k] = static_cast<std::int64_t>(corner[a][k]);
            r[k] = static_cast<std::int64_t>(corner[b][k]);
            t[k] = static_cast<std::int64_t>(corner[c][k]);
          }
          return p[0] * (r[1] * t[2] - r[2] * t[1]) - p[1] * (r[0] * t[2] - r[2] * t[0]) +
                 p[2] * (r[0] * t[1] - r[1] * t[0]);
        };
        six_volume += triple(q[0], q[1], q[2]) + triple(q[0], q[2], q[3]);
        // Its voxel: half a step inward from the face centre, along the outward normal.
        std::array<double, 3> centre{}, normal{};
        for (int a = 0; a < 3; ++a) centre[a] = (corner[q[0]][a] + corner[q[2]][a]) / 2;
        const auto &p0 = corner[q[0]], &p1 = corner[q[1]], &p2 = corner[q[2]];
        normal = {(p1[1] - p0[1]) * (p2[2] - p0[2]) - (p1[2] - p0[2]) * (p2[1] - p0[1]),
                  (p1[2] - p0[2]) * (p2[0] - p0[0]) - (p1[0] - p0[0]) * (p2[2] - p0[2]),
                  (p1[0] - p0[0]) * (p2[1] - p0[1]) - (p1[1] - p0[1]) * (p2[0] - p0[0])};
        Xyz inside, outside;
        for (int a = 0; a < 3; ++a) {
          inside[a] = static_cast<std::uint32_t>(std::floor(centre[a] - normal[a] / 2));
          outside[a] = static_cast<std::uint32_t>(std::floor(centre[a] + normal[a] / 2));
        }
        ASSERT_TRUE(s.voxels.count(inside)) << "face " << f << " does not face out of a voxel";
        ASSERT_FALSE(s.voxels.count(outside)) << "face " << f << " faces into a voxel";
        const auto rank = s.tree.rank(vola_test::to_voxel(inside));
        for (const auto& column : s.tree.attributes().columns())
          ASSERT_EQ(face.rows[f][face.index_of(column.name())], expected_ply_value(column, *rank));
      }
      EXPECT_EQ(six_volume, 6 * static_cast<std::int64_t>(s.voxels.size()));
      EXPECT_TRUE(std::all_of(used.begin(), used.end(), [](bool u) { return u; })) << "unused vertices";
      // Closed: every edge is shared by an even number of faces (2, or 4 where voxels meet
      // along an edge only).
      for (const auto& [edge, count] : edges) ASSERT_EQ(count % 2, 0);
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Depths, PlyCubesRandom, ::testing::Range(1, 7));

}  // namespace
