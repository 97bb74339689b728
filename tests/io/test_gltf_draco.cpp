// glTF scenes whose primitives are Draco-compressed (KHR_draco_mesh_compression), written
// here with libdraco's encoder from meshes whose triangles are known exactly. Debian 12's
// Assimp refuses such a scene when its indices are 32-bit (every Draco mesh of more than
// 65,535 vertices); vola decodes the primitives itself first (src/io/plugins/gltf_draco.hpp).
#include <algorithm>
#include <cstring>
#include <string>
#include <vector>

#include <draco/compression/encode.h>
#include <draco/mesh/triangle_soup_mesh_builder.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "../mesh/mesh_test_support.hpp"
#include "vola/error.hpp"
#include "vola/io/mesh.hpp"

namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using vola::io::Triangle;

// A height field of n x n vertices (two triangles a square), every coordinate exact in float.
std::vector<Triangle> grid_mesh(int n) {
  const auto vertex = [](int i, int j) { return vola::Point{0.5 * i, 0.25 * j, double((i * j) % 7)}; };
  std::vector<Triangle> triangles;
  for (int i = 0; i + 1 < n; ++i)
    for (int j = 0; j + 1 < n; ++j) {
      triangles.push_back({vertex(i, j), vertex(i + 1, j), vertex(i, j + 1)});
      triangles.push_back({vertex(i + 1, j), vertex(i + 1, j + 1), vertex(i, j + 1)});
    }
  return triangles;
}

// Triangles compared as sets of corners: Draco renumbers vertices and reorders faces.
std::vector<Triangle> canonical(std::vector<Triangle> triangles) {
  for (Triangle& t : triangles) std::sort(t.begin(), t.end());
  std::sort(triangles.begin(), triangles.end());
  return triangles;
}

struct Encoded {
  std::string bytes;
  std::uint32_t position_id = 0;
  std::uint32_t points = 0;
};

Encoded draco_encoded(const std::vector<Triangle>& triangles) {
  draco::TriangleSoupMeshBuilder builder;
  builder.Start(static_cast<int>(triangles.size()));
  const int position = builder.AddAttribute(draco::GeometryAttribute::POSITION, 3, draco::DT_FLOAT32);
  for (std::size_t f = 0; f < triangles.size(); ++f) {
    float corners[3][3];
    for (int k = 0; k < 3; ++k)
      for (int a = 0; a < 3; ++a) corners[k][a] = static_cast<float>(triangles[f][k][a]);
    builder.SetAttributeValuesForFace(position, draco::FaceIndex(static_cast<std::uint32_t>(f)), corners[0], corners[1],
                                      corners[2]);
  }
  const std::unique_ptr<draco::Mesh> mesh = builder.Finalize();
  draco::Encoder encoder;  // no quantization: the positions come back exactly
  draco::EncoderBuffer buffer;
  EXPECT_TRUE(encoder.EncodeMeshToBuffer(*mesh, &buffer).ok());
  return {std::string(buffer.data(), buffer.size()), mesh->attribute(position)->unique_id(), mesh->num_points()};
}

// The scene of one Draco primitive; `index_type` is its indices accessor's component type
// (5123 16-bit, 5125 32-bit), `draco_buffer` the buffer holding the Draco bytes.
json draco_scene(const Encoded& draco, int index_type, std::size_t faces) {
  return {{"asset", {{"version", "2.0"}}},
          {"extensionsUsed", {"KHR_draco_mesh_compression"}},
          {"extensionsRequired", {"KHR_draco_mesh_compression"}},
          {"scene", 0},
          {"scenes", {{{"nodes", {0}}}}},
          {"nodes", {{{"mesh", 0}, {"translation", {100, 0, 0}}}}},
          {"meshes",
           {{{"primitives",
              {{{"attributes", {{"POSITION", 0}, {"NORMAL", 2}}},
                {"indices", 1},
                {"mode", 4},
                {"extensions",
                 {{"KHR_draco_mesh_compression",
                   {{"bufferView", 0}, {"attributes", {{"POSITION", draco.position_id}}}}}}}}}}}}},
          {"accessors",
           {{{"componentType", 5126}, {"count", draco.points}, {"type", "VEC3"}},
            {{"componentType", index_type}, {"count", 3 * faces}, {"type", "SCALAR"}},
            {{"componentType", 5126}, {"count", draco.points}, {"type", "VEC3"}}}},
          {"bufferViews", {{{"buffer", 0}, {"byteOffset", 0}, {"byteLength", draco.bytes.size()}}}},
          {"buffers", {{{"byteLength", draco.bytes.size()}}}}};
}

void append_u32(std::string& out, std::uint32_t v) { out.append(reinterpret_cast<const char*>(&v), 4); }

std::string glb(const json& scene, std::string bin) {
  std::string text = scene.dump();
  text.append((4 - text.size() % 4) % 4, ' ');
  bin.append((4 - bin.size() % 4) % 4, '\0');
  std::string out = "glTF";
  append_u32(out, 2);
  append_u32(out, static_cast<std::uint32_t>(28 + text.size() + bin.size()));
  append_u32(out, static_cast<std::uint32_t>(text.size()));
  out += "JSON";
  out += text;
  append_u32(out, static_cast<std::uint32_t>(bin.size()));
  out += std::string("BIN\0", 4);
  out += bin;
  return out;
}

std::string base64(const std::string& raw) {
  static const char* kAlphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string encoded;
  for (std::size_t i = 0; i < raw.size(); i += 3) {
    std::uint32_t chunk = static_cast<std::uint8_t>(raw[i]) << 16;
    if (i + 1 < raw.size()) chunk |= static_cast<std::uint8_t>(raw[i + 1]) << 8;
    if (i + 2 < raw.size()) chunk |= static_cast<std::uint8_t>(raw[i + 2]);
    const std::size_t bytes = std::min<std::size_t>(3, raw.size() - i);
    for (std::size_t k = 0; k < 4; ++k) encoded += k <= bytes ? kAlphabet[(chunk >> (18 - 6 * k)) & 63] : '=';
  }
  return encoded;
}

std::vector<Triangle> moved(std::vector<Triangle> triangles, double dx) {
  for (Triangle& t : triangles)
    for (vola::Point& p : t) p[0] += dx;
  return triangles;
}

TEST(GltfDraco, ThirtyTwoBitIndicesAreReadWhole) {
  // 260 x 260 = 67,600 vertices: more than 16-bit indices reach, as in any large scan.
  const std::vector<Triangle> mesh = grid_mesh(260);
  const Encoded draco = draco_encoded(mesh);
  ASSERT_GT(draco.points, 65535u);
  vola_test::TempDir dir;
  write_file(dir / "big.glb", glb(draco_scene(draco, 5125, mesh.size()), draco.bytes));
  const auto triangles = vola::io::read_mesh_triangles((dir / "big.glb").string());
  EXPECT_EQ(canonical(triangles), canonical(moved(mesh, 100)));  // the node's translation applied
}

TEST(GltfDraco, SixteenBitIndicesAndDataUrisAreReadAlike) {
  const std::vector<Triangle> mesh = grid_mesh(40);
  const Encoded draco = draco_encoded(mesh);
  const auto expected = canonical(moved(mesh, 100));
  vola_test::TempDir dir;
  write_file(dir / "small.glb", glb(draco_scene(draco, 5123, mesh.size()), draco.bytes));
  EXPECT_EQ(canonical(vola::io::read_mesh_triangles((dir / "small.glb").string())), expected);

  // A .gltf with the Draco bytes in a data: URI, after a plain buffer that the new binary
  // chunk moves up by one.
  json scene = draco_scene(draco, 5125, mesh.size());
  scene["buffers"] = {
      {{"byteLength", 4}, {"uri", "data:application/octet-stream;base64,AAAAAA=="}},
      {{"byteLength", draco.bytes.size()}, {"uri", "data:application/octet-stream;base64," + base64(draco.bytes)}}};
  scene["bufferViews"][0]["buffer"] = 1;
  write_file(dir / "text.gltf", scene.dump());
  EXPECT_EQ(canonical(vola::io::read_mesh_triangles((dir / "text.gltf").string())), expected);
}

TEST(GltfDraco, BadDracoDataIsAFormatErrorNamingTheFileAndOffset) {
  const std::vector<Triangle> mesh = grid_mesh(20);
  const Encoded draco = draco_encoded(mesh);
  vola_test::TempDir dir;
  const auto error_of = [&](const std::string& name, const std::string& bytes) {
    write_file(dir / name, bytes);
    const std::string path = (dir / name).string();
    auto error = vola_test::format_error_of([&] { vola::io::read_mesh_triangles(path); });
    EXPECT_TRUE(error.has_value()) << name;
    if (error) {
      EXPECT_EQ(error->file(), path);
    }
    return error;
  };

  // The Draco stream cut short: the error points at its first byte in the file.
  const json scene = draco_scene(draco, 5125, mesh.size());
  std::string cut = draco.bytes.substr(0, draco.bytes.size() / 2);
  json cut_scene = scene;
  cut_scene["bufferViews"][0]["byteLength"] = cut.size();
  cut_scene["buffers"][0]["byteLength"] = cut.size();
  const std::string cut_file = glb(cut_scene, cut);
  const auto truncated = error_of("cut.glb", cut_file);
  ASSERT_TRUE(truncated.has_value());
  EXPECT_NE(truncated->cause().find("mesh 0 primitive 0: Draco"), std::string::npos) << truncated->cause();
  ASSERT_TRUE(truncated->offset().has_value());
  EXPECT_EQ(std::memcmp(cut_file.data() + *truncated->offset(), cut.data(), 16), 0)
      << "offset " << *truncated->offset();

  // A buffer view past the end of its buffer, or one that does not exist.
  json past = scene;
  past["bufferViews"][0]["byteOffset"] = 8;
  const auto beyond = error_of("past.glb", glb(past, draco.bytes));
  ASSERT_TRUE(beyond.has_value());
  EXPECT_NE(beyond->cause().find("past the end of its buffer"), std::string::npos) << beyond->cause();
  json missing = scene;
  missing["meshes"][0]["primitives"][0]["extensions"]["KHR_draco_mesh_compression"]["bufferView"] = 7;
  const auto absent = error_of("absent.glb", glb(missing, draco.bytes));
  ASSERT_TRUE(absent.has_value());
  EXPECT_NE(absent->cause().find("buffer view 7, which the scene does not have"), std::string::npos) << absent->cause();

  // No POSITION among the Draco attributes, or one the stream does not hold.
  json unnamed = scene;
  unnamed["meshes"][0]["primitives"][0]["extensions"]["KHR_draco_mesh_compression"]["attributes"] = {{"POSITION", 9}};
  const auto unheld = error_of("unheld.glb", glb(unnamed, draco.bytes));
  ASSERT_TRUE(unheld.has_value());
  EXPECT_NE(unheld->cause().find("no three-component attribute 9"), std::string::npos) << unheld->cause();

  // The Draco bytes in another file are not read.
  json outside = scene;
  outside["buffers"][0]["uri"] = "mesh.drc";
  write_file(dir / "mesh.drc", draco.bytes);
  const auto elsewhere = error_of("outside.gltf", outside.dump());
  ASSERT_TRUE(elsewhere.has_value());
  EXPECT_NE(elsewhere->cause().find("lies in another file, 'mesh.drc'"), std::string::npos) << elsewhere->cause();
}

}  // namespace
