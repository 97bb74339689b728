// Meshes through Assimp: the shared files against EXPECTED.txt, and small files written
// here whose triangles are known exactly.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>

#include <gtest/gtest.h>
#include <sys/stat.h>

#include "../mesh/mesh_test_support.hpp"
#include "memory_cap.hpp"
#include "vola/error.hpp"
#include "vola/io/input.hpp"
#include "vola/io/mesh.hpp"
#include "vola/mesh/voxelize.hpp"

namespace {

namespace fs = std::filesystem;
using vola::Point;
using vola::io::Triangle;

struct Expected {
  std::uint64_t triangles = 0;
  Point min{}, max{};
};

// The EXPECTED.txt line of `name`: triangles=N (STL), tri=N (OFF) or f=N (OBJ, whose
// faces in these files are all triangles), and bbox=[..]..[..].
std::optional<Expected> expected_for(const fs::path& data, const std::string& name) {
  std::ifstream in(data / "EXPECTED.txt");
  std::string line;
  const std::regex count(R"((?:triangles=|\(tri=| f=)(\d+))");
  const std::regex box(R"(bbox=\[([-\d.e]+), ([-\d.e]+), ([-\d.e]+)\]\.\.\[([-\d.e]+), ([-\d.e]+), ([-\d.e]+)\])");
  while (std::getline(in, line)) {
    if (line.rfind(name + " ", 0) != 0) continue;
    std::smatch c, b;
    if (!std::regex_search(line, c, count) || !std::regex_search(line, b, box)) return std::nullopt;
    Expected e;
    e.triangles = std::stoull(c[1]);
    for (int a = 0; a < 3; ++a) {
      e.min[a] = std::stod(b[1 + a]);
      e.max[a] = std::stod(b[4 + a]);
    }
    return e;
  }
  return std::nullopt;
}

vola::Box bounds(const std::vector<Triangle>& triangles) { return vola::mesh::triangle_bounds(triangles); }

// The bbox of the vertices some face uses, read the slow obvious way from an OFF or OBJ
// file (EXPECTED.txt's bbox covers every vertex; a few ModelNet files have vertices no
// face uses, which the reader leaves out). `all_used` says whether every vertex is used.
vola::Box used_vertex_bounds(const fs::path& path, bool& all_used) {
  std::vector<Point> vertices;
  std::vector<long> used;
  std::ifstream in(path);
  if (path.extension() == ".off") {
    std::string magic;
    long nv = 0, nf = 0, ne = 0;
    in >> magic >> nv >> nf >> ne;
    vertices.resize(static_cast<std::size_t>(nv));
    for (auto& v : vertices) in >> v[0] >> v[1] >> v[2];
    for (long f = 0; f < nf; ++f) {
      long n = 0;
      in >> n;
      for (long k = 0; k < n; ++k) {
        long i = 0;
        in >> i;
        used.push_back(i);
      }
      std::string rest;
      std::getline(in, rest);  // colours, if any
    }
  } else {
    std::string line;
    while (std::getline(in, line)) {
      std::istringstream words(line);
      std::string tag;
      words >> tag;
      if (tag == "v") {
        Point p;
        words >> p[0] >> p[1] >> p[2];
        vertices.push_back(p);
      } else if (tag == "f") {
        for (std::string ref; words >> ref;) {
          const long i = std::stol(ref.substr(0, ref.find('/')));
          used.push_back(i < 0 ? static_cast<long>(vertices.size()) + i : i - 1);
        }
      }
    }
  }
  std::vector<bool> seen(vertices.size(), false);
  for (long i : used) seen.at(static_cast<std::size_t>(i)) = true;
  all_used = std::find(seen.begin(), seen.end(), false) == seen.end();
  std::vector<Triangle> points;
  for (std::size_t i = 0; i < vertices.size(); ++i)
    if (seen[i]) points.push_back({vertices[i], vertices[i], vertices[i]});
  return bounds(points);
}

TEST(MeshAssimp, SharedFilesMatchExpected) {
  VOLA_REQUIRE_DATA(data);
  int files = 0, checked = 0, partly_used = 0;
  for (const char* folder : {"mesh/stl", "mesh/obj", "mesh/off", "modelnet/off"}) {
    for (const auto& entry : fs::directory_iterator(data / folder)) {
      const std::string name = entry.path().filename().string();
      SCOPED_TRACE(name);
      ++files;
      const vola::io::Input input = vola::io::read_input(entry.path().string(), "auto", {});
      EXPECT_EQ(input.format, "mesh");
      ASSERT_FALSE(input.triangles.empty());
      const vola::Box got = bounds(input.triangles);
      bool all_used = true;
      if (entry.path().extension() != ".stl") {
        const vola::Box used = used_vertex_bounds(entry.path(), all_used);
        partly_used += !all_used;
        for (int a = 0; a < 3; ++a) {  // Assimp keeps 32-bit floats
          EXPECT_NEAR(got.min[a], used.min[a], 1e-6 * (1 + std::abs(used.min[a]))) << "axis " << a;
          EXPECT_NEAR(got.max[a], used.max[a], 1e-6 * (1 + std::abs(used.max[a]))) << "axis " << a;
        }
      }
      const auto expected = expected_for(data, name);
      if (!expected) continue;  // nothing recorded: reading it is the test
      ++checked;
      EXPECT_EQ(input.triangles.size(), expected->triangles);
      for (int a = 0; a < 3; ++a) {
        // EXPECTED.txt prints 4 decimals of the bbox of every vertex.
        const double tolerance = 6e-5 + 1e-6 * std::abs(expected->max[a]);
        if (all_used) {
          EXPECT_NEAR(got.min[a], expected->min[a], tolerance) << "axis " << a;
          EXPECT_NEAR(got.max[a], expected->max[a], tolerance) << "axis " << a;
        } else {
          EXPECT_GE(got.min[a], expected->min[a] - tolerance) << "axis " << a;
          EXPECT_LE(got.max[a], expected->max[a] + tolerance) << "axis " << a;
        }
      }
    }
  }
  EXPECT_GE(files, 18);
  EXPECT_GE(checked, 18);
  EXPECT_GE(partly_used, 1);  // the case above is exercised
}

void write_file(const fs::path& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary).write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

// A binary STL: 80-byte header, count, then per triangle normal + 3 vertices + 2 bytes.
std::string binary_stl(const std::string& header, const std::vector<std::array<float, 9>>& triangles) {
  std::string out = header;
  out.resize(80, ' ');
  const std::uint32_t n = static_cast<std::uint32_t>(triangles.size());
  out.append(reinterpret_cast<const char*>(&n), 4);
  for (const auto& t : triangles) {
    const float normal[3] = {0, 0, 0};
    out.append(reinterpret_cast<const char*>(normal), 12);
    out.append(reinterpret_cast<const char*>(t.data()), 36);
    out.append(2, '\0');
  }
  return out;
}

const std::vector<std::array<float, 9>> kTetrahedron = {
    {0, 0, 0, 1, 0, 0, 0, 1, 0}, {0, 0, 0, 0, 0, 1, 1, 0, 0}, {0, 0, 0, 0, 1, 0, 0, 0, 1}, {1, 0, 0, 0, 0, 1, 0, 1, 0}};

void expect_tetrahedron(const std::vector<Triangle>& got, const Point& shift = {0, 0, 0}) {
  ASSERT_EQ(got.size(), kTetrahedron.size());
  for (std::size_t i = 0; i < got.size(); ++i)
    for (int k = 0; k < 3; ++k)
      for (int a = 0; a < 3; ++a) EXPECT_EQ(got[i][k][a], kTetrahedron[i][3 * k + a] + shift[a]) << i << " " << k;
}

TEST(MeshAssimp, BinaryStlWhoseHeaderSaysSolid) {
  vola_test::TempDir dir;
  write_file(dir / "plain.stl", binary_stl("binary", kTetrahedron));
  write_file(dir / "solid.stl", binary_stl("solid tetrahedron, but binary", kTetrahedron));
  expect_tetrahedron(vola::io::read_mesh_triangles((dir / "plain.stl").string()));
  expect_tetrahedron(vola::io::read_mesh_triangles((dir / "solid.stl").string()));
}

TEST(MeshAssimp, RealBinaryStlWithASolidHeader) {
  VOLA_REQUIRE_DATA(data);
  const auto original = vola_test::read_bytes(data / "mesh/stl/trimesh_teapot_bin.stl");
  std::string bytes(original.begin(), original.end());
  bytes.replace(0, 11, "solid teapo");
  vola_test::TempDir dir;
  write_file(dir / "teapot.stl", bytes);
  const auto a = vola::io::read_mesh_triangles((data / "mesh/stl/trimesh_teapot_bin.stl").string());
  const auto b = vola::io::read_mesh_triangles((dir / "teapot.stl").string());
  EXPECT_EQ(a, b);
  EXPECT_EQ(a.size(), 894u);
}

TEST(MeshAssimp, AsciiStl) {
  vola_test::TempDir dir;
  std::string text = "solid tetra\n";
  for (const auto& t : kTetrahedron) {
    text += " facet normal 0 0 0\n  outer loop\n";
    for (int k = 0; k < 3; ++k)
      text += "   vertex " + std::to_string(t[3 * k]) + " " + std::to_string(t[3 * k + 1]) + " " +
              std::to_string(t[3 * k + 2]) + "\n";
    text += "  endloop\n endfacet\n";
  }
  text += "endsolid tetra\n";
  write_file(dir / "tetra.stl", text);
  expect_tetrahedron(vola::io::read_mesh_triangles((dir / "tetra.stl").string()));
}

TEST(MeshAssimp, PolygonsAreTriangulatedLinesAndPointsKept) {
  vola_test::TempDir dir;
  write_file(dir / "quad.off", "OFF\n5 2 0\n0 0 0\n2 0 0\n2 3 0\n0 3 0\n7 7 7\n4 0 1 2 3\n3 0 1 4\n");
  EXPECT_EQ(vola::io::read_mesh_triangles((dir / "quad.off").string()).size(), 3u);
  write_file(dir / "mixed.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 5 5 5\nf 1 2 3 4\nl 1 5\n");
  const auto mixed = vola::io::read_mesh_triangles((dir / "mixed.obj").string());
  ASSERT_EQ(mixed.size(), 3u);
  int segments = 0;
  for (const Triangle& t : mixed)
    if (t[1] == t[2] && t[0] != t[1]) {
      ++segments;
      EXPECT_TRUE((t[0] == Point{0, 0, 0} && t[1] == Point{5, 5, 5}) || (t[0] == Point{5, 5, 5} && t[1] == Point{0, 0, 0}));
    }
  EXPECT_EQ(segments, 1);
}

// An OBJ of vertices alone (a point cloud, as CloudCompare writes one): Assimp's
// validation refuses its faceless mesh, so vola reads it again and keeps the vertices as
// points; vertices of an object without faces beside one with faces stay out, as before.
TEST(MeshAssimp, ObjOfVerticesAloneIsPoints) {
  vola_test::TempDir dir;
  write_file(dir / "points.obj", "# a scan\nv 1 2 3\nv 4 5 6.5\nv -1 0 0\n");
  const auto points = vola::io::read_mesh_triangles((dir / "points.obj").string());
  ASSERT_EQ(points.size(), 3u);
  std::vector<Point> got;
  for (const Triangle& t : points) {
    EXPECT_TRUE(t[0] == t[1] && t[1] == t[2]);
    got.push_back(t[0]);
  }
  std::sort(got.begin(), got.end());
  EXPECT_EQ(got, (std::vector<Point>{{-1, 0, 0}, {1, 2, 3}, {4, 5, 6.5}}));
  // A face naming a vertex that does not exist is still refused, not read as points.
  write_file(dir / "mixed.obj", "o a\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\no b\nv 5 5 5\n");
  EXPECT_EQ(vola::io::read_mesh_triangles((dir / "mixed.obj").string()).size(), 1u);
  write_file(dir / "bad.obj", "v 1 2 3\nf 1 2 9\n");
  EXPECT_TRUE(vola_test::format_error_of([&] { vola::io::read_mesh_triangles((dir / "bad.obj").string()); }));
}

// glTF nodes: a parent scaled by 2 and moved by (10, 0, 0), a child moved by (0, 1, 0)
// in the parent's frame, both placing one triangle (0,0,0) (1,0,0) (0,1,0).
TEST(MeshAssimp, NodeTransformsAreApplied) {
  float positions[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  std::string raw(reinterpret_cast<const char*>(positions), sizeof positions);
  static const char* kBase64 = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string encoded;
  for (std::size_t i = 0; i < raw.size(); i += 3) {
    const std::uint32_t chunk = (static_cast<std::uint8_t>(raw[i]) << 16) |
                                (i + 1 < raw.size() ? static_cast<std::uint8_t>(raw[i + 1]) << 8 : 0) |
                                (i + 2 < raw.size() ? static_cast<std::uint8_t>(raw[i + 2]) : 0);
    for (int k = 0; k < 4; ++k)
      encoded += i * 8 + 6 * k < raw.size() * 8 ? kBase64[(chunk >> (18 - 6 * k)) & 63] : '=';
  }
  const std::string gltf = R"({"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0]}],
  "nodes":[{"mesh":0,"translation":[10,0,0],"scale":[2,2,2],"children":[1]},{"mesh":0,"translation":[0,1,0]}],
  "meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}],
  "accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}],
  "bufferViews":[{"buffer":0,"byteOffset":0,"byteLength":36}],
  "buffers":[{"byteLength":36,"uri":"data:application/octet-stream;base64,)" + encoded + R"("}]})";
  vola_test::TempDir dir;
  write_file(dir / "nodes.gltf", gltf);
  auto triangles = vola::io::read_mesh_triangles((dir / "nodes.gltf").string());
  ASSERT_EQ(triangles.size(), 2u);
  std::sort(triangles.begin(), triangles.end());
  // Parent: 2 * p + (10, 0, 0). Child: 2 * (p + (0, 1, 0)) + (10, 0, 0).
  EXPECT_EQ(triangles[0], (Triangle{{{10, 0, 0}, {12, 0, 0}, {10, 2, 0}}}));
  EXPECT_EQ(triangles[1], (Triangle{{{10, 2, 0}, {12, 2, 0}, {10, 4, 0}}}));
}

TEST(MeshAssimp, BadFilesThrowFormatErrorsNamingTheFile) {
  vola_test::TempDir dir;
  const auto expect_error = [&](const std::string& name, const std::string& bytes) {
    write_file(dir / name, bytes);
    const std::string path = (dir / name).string();
    const auto error = vola_test::format_error_of([&] { vola::io::read_mesh_triangles(path); });
    ASSERT_TRUE(error.has_value()) << name;
    EXPECT_EQ(error->file(), path);
    EXPECT_FALSE(error->cause().empty());
  };
  expect_error("empty.stl", "");
  std::string truncated = binary_stl("binary", kTetrahedron);
  truncated.resize(120);
  expect_error("truncated.stl", truncated);
  expect_error("bad_index.obj", "v 0 0 0\nv 1 0 0\nf 1 2 9\n");
  expect_error("garbage.off", "OFF\n3 1 0\n0 0\n");
  expect_error("not_a_header.off", "\x02OFF\n4 1 0\n0 0 0\n");  // a byte before OFF
  // Header counts the file cannot hold are refused before anything is reserved (found
  // by fuzz_mesh_read: Assimp allocated gigabytes for a 143-byte file).
  for (const auto& [name, bytes] : {std::pair<std::string, std::string>{"lying_faces.off", "OFF\n4 33333333333333333333333333 0\n0 0 0\n"},
                                    {"lying_vertices.off", "OFF 400000000 1 0\n0 0 0\n3 0 0 0\n"}}) {
    write_file(dir / name, bytes);
    const auto error = vola_test::format_error_of([&] { vola::io::read_mesh_triangles((dir / name).string()); });
    ASSERT_TRUE(error.has_value()) << name;
    EXPECT_NE(error->cause().find("more than the file's"), std::string::npos) << error->cause();
  }
  expect_error("nothing.obj", "# only a comment\n");
  // Only the importer of the file's extension reads it: this .gltf went to Assimp's
  // Quick3D importer (whose signature it begins with), which asked for 1.5 TB.
  const std::string quick3d("quick3ds\x80\x02\x00\x00\x10\x02\x00\x00JSON{\"asset\":{\"version\":\"2.0\"}}", 47);
  write_file(dir / "quick3d.gltf", quick3d);
  const auto not_gltf =
      vola_test::format_error_of([&] { vola::io::read_mesh_triangles((dir / "quick3d.gltf").string()); });
  ASSERT_TRUE(not_gltf.has_value());
  EXPECT_EQ(not_gltf->cause().find("Quick3D"), std::string::npos) << not_gltf->cause();
  EXPECT_THROW(vola::io::read_mesh_triangles((dir / "missing.stl").string()), vola::IoError);
  EXPECT_TRUE(vola_test::format_error_of([&] { vola::io::read_mesh_triangles((dir / "missing.obj").string()); }));
}

// OFF headers whose counts the file cannot hold: each made Assimp allocate gigabytes for
// a file of under 60 bytes (8.6 GB of faces here) before vola read OFF itself; the
// counts are refused before anything is reserved. Run under a 2 GiB address-space cap.
TEST(MeshAssimp, OffCountsTheFileCannotHoldAreRefused) {
  vola_test::TempDir dir;
  const std::pair<std::string, std::string> hostile[] = {
      {"no_keyword.off", "1 536870911 0\n0 0 0\n3 0 0 0\n"},                  // no "OFF": the counts anyway
      {"dimension.off", "nOFF 3 1 536870911 0\n0 0 0\n3 0 0 0\n"},            // the n prefix adds a dimension first
      {"prefixes.off", "STCN4nOFF 3 1 536870911 0\n0 0 0 1\n3 0 0 0\n"},      // every prefix
      {"commented.off", "# a comment line\n#\nOFF\n1 536870911 0\n0 0 0\n"},  // counts after '#' lines
      {"wrapped.off", "OFF\n1 4831838207 0\n0 0 0\n3 0 0 0\n"},               // past 2^32 (Assimp's count wrapped)
      {"huge.off", "OFF\n4 33333333333333333333333333 0\n0 0 0\n"},           // past 2^64
  };
  for (const auto& [name, bytes] : hostile) {
    write_file(dir / name, bytes);
    const std::string path = (dir / name).string();
    const std::string outcome = vola_test::run_with_memory_cap([&] {
      vola::io::read_mesh_triangles(path);
      return std::string("read");
    });
    EXPECT_NE(outcome.find("FormatError: " + path + ": byte "), std::string::npos) << name << ": " << outcome;
    EXPECT_NE(outcome.find("faces, more than the file's"), std::string::npos) << name << ": " << outcome;
  }
}

// A scene that names other files (a glTF buffer's URI, an OBJ's material library) made
// Assimp open them: the bytes of any local file became vertices, a FIFO blocked forever, a
// large file was read whole. Only the given file is read now; the triangle below is the
// other file's floats, so reading it would show.
TEST(MeshAssimp, ScenesCannotReadOtherFiles) {
  vola_test::TempDir dir;
  const float positions[9] = {11, 12, 13, 21, 22, 23, 31, 32, 33};
  write_file(dir / "secret.bin", std::string(reinterpret_cast<const char*>(positions), sizeof positions));
  ASSERT_EQ(::mkfifo((dir / "fifo").c_str(), 0600), 0);
  const auto gltf = [](const std::string& uri) {
    return R"({"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0]}],"nodes":[{"mesh":0}],
    "meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}],
    "accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[11,12,13],"max":[31,32,33]}],
    "bufferViews":[{"buffer":0,"byteOffset":0,"byteLength":36}],
    "buffers":[{"byteLength":36,"uri":")" + uri + R"("}]})";
  };
  fs::create_directories(dir / "sub");
  const std::pair<fs::path, std::string> scenes[] = {
      {dir / "absolute.gltf", (dir / "secret.bin").string()},
      {dir / "sub" / "parent.gltf", "../secret.bin"},
      {dir / "beside.gltf", "secret.bin"},
      {dir / "fifo.gltf", (dir / "fifo").string()},
  };
  for (const auto& [path, uri] : scenes) {
    write_file(path, gltf(uri));
    const auto error = vola_test::format_error_of([&] { vola::io::read_mesh_triangles(path.string()); });
    ASSERT_TRUE(error.has_value()) << path;
    EXPECT_NE(error->cause().find("the scene's data lies in another file, '"), std::string::npos) << error->cause();
    EXPECT_NE(error->cause().find(uri.substr(uri.rfind('/') + 1) + "'"), std::string::npos) << error->cause();
  }
  // An OBJ's material library is not geometry: the triangle is read, the library never opened.
  write_file(dir / "fifo_mtl.obj", "mtllib " + (dir / "fifo").string() + "\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  EXPECT_EQ(vola::io::read_mesh_triangles((dir / "fifo_mtl.obj").string()).size(), 1u);
}

// Assimp 5.2's OBJ importer labels the primitive types of a mesh whose first face has two
// corners wrongly, and its own validation refuses the scene ("mFaces[0] is a LINE but
// mPrimitiveTypes does not report the LINE flag"). vola reads it again without that
// validation: the line (a degenerate triangle) and the triangle, each where the file puts
// it; a missing material library is not blamed for the failure.
TEST(MeshAssimp, MislabelledPrimitiveTypesAreReadWithTheStructureChecked) {
  vola_test::TempDir dir;
  write_file(dir / "line_first.obj", "mtllib absent.mtl\no strip\nv -5 0 5\nv 5 0 5\nv 5 5 5\nusemtl Material\n"
                                     "f 1// 2//\nf 1// 2// 3//\n");
  const auto triangles = vola::io::read_mesh_triangles((dir / "line_first.obj").string());
  ASSERT_EQ(triangles.size(), 2u);
  const vola::Point a{-5, 0, 5}, b{5, 0, 5}, c{5, 5, 5};
  std::vector<vola::io::Triangle> want = {{a, b, b}, {a, b, c}};
  auto sorted = triangles;
  std::sort(sorted.begin(), sorted.end());
  std::sort(want.begin(), want.end());
  EXPECT_EQ(sorted, want);
}

// An ASCII STL whose second solid is empty (CAD exporters write one for an empty body;
// Assimp's test model triangle_with_empty_solid.stl is one): Assimp's validation refuses
// the empty mesh, yet the file's one triangle is all there is to read. An STL of empty
// solids alone still holds nothing to voxelise.
TEST(MeshAssimp, AnEmptySolidBesideARealOneIsPassedOver) {
  vola_test::TempDir dir;
  write_file(dir / "two_solids.stl",
             "solid part\n  facet normal 0 0 1\n    outer loop\n      vertex 1 1 0\n      vertex -1 1 0\n"
             "      vertex 0 -1 0\n    endloop\n  endfacet\nendsolid part\nsolid empty\nendsolid empty\n");
  const auto triangles = vola::io::read_mesh_triangles((dir / "two_solids.stl").string());
  ASSERT_EQ(triangles.size(), 1u);
  auto corners = triangles[0];
  std::sort(corners.begin(), corners.end());
  EXPECT_EQ(corners, (vola::io::Triangle{vola::Point{-1, 1, 0}, vola::Point{0, -1, 0}, vola::Point{1, 1, 0}}));
  write_file(dir / "empty.stl", "solid empty\nendsolid empty\n");
  EXPECT_TRUE(vola_test::format_error_of([&] { vola::io::read_mesh_triangles((dir / "empty.stl").string()); }));
}

TEST(MeshAssimp, OnlyTheDocumentedMeshFormatsReachAssimp) {
  vola_test::TempDir dir;
  // An ASCII PLY (vola reads PLY itself) and a Wavefront OBJ named .md5mesh: Assimp would read both.
  write_file(dir / "tetra.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                                "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
                                "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
  write_file(dir / "tri.md5mesh", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  for (const char* name : {"tetra.ply", "tri.md5mesh"}) {
    const auto error = vola_test::format_error_of([&] { vola::io::read_mesh_triangles((dir / name).string()); });
    ASSERT_TRUE(error.has_value()) << name;
    EXPECT_NE(error->cause().find("meshes are read from .stl, .off, .obj"), std::string::npos) << error->cause();
  }
  write_file(dir / "tri.OBJ", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  EXPECT_EQ(vola::io::read_mesh_triangles((dir / "tri.OBJ").string()).size(), 1u);
}

TEST(MeshAssimp, RegisteredForItsExtensionsButNotPly) {
  for (const char* ext : {".stl", ".STL", ".obj", ".off", ".gltf", ".glb", ".dae", ".3ds"})
    EXPECT_EQ(vola::io::find_input_format(std::string("x") + ext).name, "mesh") << ext;
  EXPECT_NE(vola::io::find_input_format("x.ply").name, "mesh");
}

}  // namespace
