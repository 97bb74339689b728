// Seeds for fuzz_mesh_read: the small mesh files of the shared data folder (beside
// golden/) and a tetrahedron in each kind the entry point picks (STL ascii and binary,
// OBJ, OFF, glTF with an embedded buffer, a .glb whose primitive is Draco-compressed), each
// prefixed with its selector byte.
// Linked into fuzz_mesh_read_replay in place of fuzz_seeds.cpp.
#include <algorithm>
#include <cstring>
#include <fstream>
#include <iterator>
#include <string>

#include <draco/compression/encode.h>
#include <draco/mesh/triangle_soup_mesh_builder.h>

#include "fuzz_seeds.hpp"

namespace vola_fuzz {

extern const char* const kMeshExtensions[5];

namespace {

using Bytes = std::vector<std::uint8_t>;

Seed seed(const std::string& name, const std::string& extension, const Bytes& file) {
  const auto* kind = std::find_if(std::begin(kMeshExtensions), std::end(kMeshExtensions),
                                  [&](const char* e) { return extension == e; });
  Bytes bytes{static_cast<std::uint8_t>(kind - std::begin(kMeshExtensions))};
  bytes.insert(bytes.end(), file.begin(), file.end());
  return {name, std::move(bytes)};
}

Bytes text(const std::string& s) { return Bytes(s.begin(), s.end()); }

template <class T>
void put(Bytes& out, T value) {
  std::uint8_t raw[sizeof(T)];
  std::memcpy(raw, &value, sizeof(T));
  out.insert(out.end(), raw, raw + sizeof(T));
}

constexpr float kVertex[4][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
constexpr int kFace[4][3] = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};

Bytes binary_stl() {
  Bytes b(80, ' ');
  put(b, std::uint32_t{4});
  for (const auto& f : kFace) {
    for (int k = 0; k < 3; ++k) put(b, 0.0f);  // normal
    for (int v : f)
      for (int a = 0; a < 3; ++a) put(b, kVertex[v][a]);
    put(b, std::uint16_t{0});
  }
  return b;
}

std::string ascii_stl() {
  std::string s = "solid tetra\n";
  for (const auto& f : kFace) {
    s += "facet normal 0 0 0\n outer loop\n";
    for (int v : f)
      s += "  vertex " + std::to_string(kVertex[v][0]) + " " + std::to_string(kVertex[v][1]) + " " +
           std::to_string(kVertex[v][2]) + "\n";
    s += " endloop\nendfacet\n";
  }
  return s + "endsolid tetra\n";
}

// A glTF 2.0 file whose buffer (4 float vertices, 12 uint16 indices) is a data: URI.
std::string gltf() {
  Bytes buffer;
  for (const auto& v : kVertex)
    for (float c : v) put(buffer, c);
  for (const auto& f : kFace)
    for (int v : f) put(buffer, static_cast<std::uint16_t>(v));
  static const char* digits = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string base64;
  for (std::size_t i = 0; i < buffer.size(); i += 3) {
    const std::uint32_t n = buffer[i] << 16 | (i + 1 < buffer.size() ? buffer[i + 1] << 8 : 0) |
                            (i + 2 < buffer.size() ? buffer[i + 2] : 0);
    base64 += digits[n >> 18 & 63];
    base64 += digits[n >> 12 & 63];
    base64 += i + 1 < buffer.size() ? digits[n >> 6 & 63] : '=';
    base64 += i + 2 < buffer.size() ? digits[n & 63] : '=';
  }
  return R"({"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0]}],"nodes":[{"mesh":0}],)"
         R"("meshes":[{"primitives":[{"attributes":{"POSITION":0},"indices":1}]}],)"
         R"("buffers":[{"byteLength":72,"uri":"data:application/octet-stream;base64,)" +
         base64 +
         R"("}],"bufferViews":[{"buffer":0,"byteOffset":0,"byteLength":48},{"buffer":0,"byteOffset":48,"byteLength":24}],)"
         R"("accessors":[{"bufferView":0,"componentType":5126,"count":4,"type":"VEC3","min":[0,0,0],"max":[1,1,1]},)"
         R"({"bufferView":1,"componentType":5123,"count":12,"type":"SCALAR"}]})";
}

// The tetrahedron as a .glb whose one primitive is KHR_draco_mesh_compression (32-bit
// indices, which vola decodes before Assimp sees the scene).
Bytes draco_glb() {
  draco::TriangleSoupMeshBuilder builder;
  builder.Start(4);
  const int position = builder.AddAttribute(draco::GeometryAttribute::POSITION, 3, draco::DT_FLOAT32);
  for (std::uint32_t f = 0; f < 4; ++f)
    builder.SetAttributeValuesForFace(position, draco::FaceIndex(f), kVertex[kFace[f][0]], kVertex[kFace[f][1]],
                                      kVertex[kFace[f][2]]);
  const auto mesh = builder.Finalize();
  draco::Encoder encoder;
  draco::EncoderBuffer encoded;
  if (!encoder.EncodeMeshToBuffer(*mesh, &encoded).ok()) return {};
  Bytes bin(encoded.data(), encoded.data() + encoded.size());
  const std::size_t draco_bytes = bin.size();
  bin.resize((bin.size() + 3) / 4 * 4, 0);
  std::string json =
      R"({"asset":{"version":"2.0"},"extensionsRequired":["KHR_draco_mesh_compression"],)"
      R"("extensionsUsed":["KHR_draco_mesh_compression"],"scene":0,"scenes":[{"nodes":[0]}],"nodes":[{"mesh":0}],)"
      R"("meshes":[{"primitives":[{"attributes":{"POSITION":0},"indices":1,"extensions":)"
      R"({"KHR_draco_mesh_compression":{"bufferView":0,"attributes":{"POSITION":)" +
      std::to_string(mesh->attribute(position)->unique_id()) +
      R"(}}}}]}],)"
      R"("accessors":[{"componentType":5126,"count":)" +
      std::to_string(mesh->num_points()) +
      R"(,"type":"VEC3"},{"componentType":5125,"count":12,"type":"SCALAR"}],)"
      R"("bufferViews":[{"buffer":0,"byteLength":)" +
      std::to_string(draco_bytes) +
      R"(}],)"
      R"("buffers":[{"byteLength":)" +
      std::to_string(bin.size()) + "}]}";
  json.append((4 - json.size() % 4) % 4, ' ');
  Bytes glb = text("glTF");
  put(glb, std::uint32_t{2});
  put(glb, static_cast<std::uint32_t>(28 + json.size() + bin.size()));
  put(glb, static_cast<std::uint32_t>(json.size()));
  glb.insert(glb.end(), {'J', 'S', 'O', 'N'});
  glb.insert(glb.end(), json.begin(), json.end());
  put(glb, static_cast<std::uint32_t>(bin.size()));
  glb.insert(glb.end(), {'B', 'I', 'N', 0});
  glb.insert(glb.end(), bin.begin(), bin.end());
  return glb;
}

Bytes read_all(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return Bytes(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

}  // namespace

std::vector<Seed> synthetic_seeds() {
  std::string obj, off = "OFF\n4 4 0\n";
  for (const auto& v : kVertex) {
    const std::string xyz = std::to_string(v[0]) + " " + std::to_string(v[1]) + " " + std::to_string(v[2]) + "\n";
    obj += "v " + xyz;
    off += xyz;
  }
  for (const auto& f : kFace) {
    obj += "f " + std::to_string(f[0] + 1) + " " + std::to_string(f[1] + 1) + " " + std::to_string(f[2] + 1) + "\n";
    const std::string face = "3 " + std::to_string(f[0]) + " " + std::to_string(f[1]) + " " + std::to_string(f[2]) + "\n";
    off += face;
  }
  return {seed("tetra_ascii.stl", "stl", text(ascii_stl())),
          seed("tetra_binary.stl", "stl", binary_stl()),
          seed("tetra.obj", "obj", text(obj)),
          seed("tetra.off", "off", text(off)),
          seed("tetra.gltf", "gltf", text(gltf())),
          seed("tetra_draco.glb", "gltf", draco_glb())};
}

// The shared data folder's mesh files of at most 64 KiB (larger ones make each
// mutation slow); `golden` is $VOLA_SHARED/golden, the data folder its sibling.
std::vector<Seed> golden_seeds(const std::filesystem::path& golden) {
  std::vector<Seed> seeds;
  const auto meshes = golden.parent_path() / "data" / "mesh";
  if (!std::filesystem::is_directory(meshes)) return seeds;
  for (const auto& entry : std::filesystem::recursive_directory_iterator(meshes)) {
    const std::string extension = entry.path().extension().string();
    const bool known = std::any_of(std::begin(kMeshExtensions), std::end(kMeshExtensions),
                                   [&](const char* e) { return extension == std::string(".") + e; });
    if (entry.is_regular_file() && known && entry.file_size() <= 64 * 1024)
      seeds.push_back(seed("mesh_" + entry.path().filename().string(), extension.substr(1), read_all(entry.path())));
  }
  std::sort(seeds.begin(), seeds.end(), [](const Seed& a, const Seed& b) { return a.name < b.name; });
  return seeds;
}

}  // namespace vola_fuzz
