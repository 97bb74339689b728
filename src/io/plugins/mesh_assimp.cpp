#include <algorithm>
#include <array>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <string_view>
#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <utility>
#include <vector>

#include "vola/error.hpp"
#include "../reader_plugin.hpp"
#include "readers.hpp"
#include "vola/io/mesh.hpp"

namespace vola::io {

namespace {

using Matrix = std::array<double, 12>;  // the top three rows of an affine 4x4, row-major

Matrix to_matrix(const aiMatrix4x4& m) {
  return {m.a1, m.a2, m.a3, m.a4, m.b1, m.b2, m.b3, m.b4, m.c1, m.c2, m.c3, m.c4};
}

Matrix multiply(const Matrix& a, const Matrix& b) {
  Matrix r{};
  for (int row = 0; row < 3; ++row)
    for (int col = 0; col < 4; ++col) {
      double s = col == 3 ? a[4 * row + 3] : 0.0;
      for (int k = 0; k < 3; ++k) s += a[4 * row + k] * b[4 * k + col];
      r[4 * row + col] = s;
    }
  return r;
}

Point transform(const Matrix& m, const aiVector3D& v) {
  Point p;
  for (int row = 0; row < 3; ++row)
    p[row] = m[4 * row] * v.x + m[4 * row + 1] * v.y + m[4 * row + 2] * v.z + m[4 * row + 3];
  return p;
}

// The decimal number at text[at...] after blanks and '#' comment lines, saturating at
// 2^63; nullopt when there is none. `at` moves past it.
std::optional<std::uint64_t> next_count(std::string_view text, std::size_t& at) {
  while (at < text.size() && (std::isspace(static_cast<unsigned char>(text[at])) || text[at] == '#')) {
    if (text[at] == '#')
      while (at < text.size() && text[at] != '\n') ++at;
    else
      ++at;
  }
  if (at >= text.size() || !std::isdigit(static_cast<unsigned char>(text[at]))) return std::nullopt;
  std::uint64_t value = 0;
  for (; at < text.size() && std::isdigit(static_cast<unsigned char>(text[at])); ++at)
    value = std::min<std::uint64_t>(value * 10 + static_cast<std::uint64_t>(text[at] - '0'), std::uint64_t{1} << 63);
  return value;
}

// Assimp's OFF reader reserves the header's vertex and face counts before reading
// them: a 143-byte file declaring billions of faces made it allocate gigabytes (found
// by fuzz_mesh_read). Each vertex or face takes at least two bytes of text, so counts
// the rest of the file cannot hold are refused before Assimp sees them.
void check_off_counts(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::array<char, 1024> head{};
  in.read(head.data(), static_cast<std::streamsize>(head.size()));
  const std::string_view text(head.data(), static_cast<std::size_t>(in.gcount()));
  const std::size_t keyword = text.find("OFF");
  if (keyword == std::string_view::npos || keyword > 4) return;  // not OFF (or a prefixed ST/C/N/4 OFF)
  std::size_t at = keyword + 3;
  const std::size_t vertices_at = at;
  const std::optional<std::uint64_t> vertices = next_count(text, at);
  const std::optional<std::uint64_t> faces = vertices ? next_count(text, at) : std::nullopt;
  if (!faces) return;  // Assimp reports a header it cannot read itself
  std::error_code error;
  const std::uint64_t bytes = std::filesystem::file_size(path, error);
  if (error) return;
  if (*vertices > bytes / 2 || *faces > bytes / 2 || *vertices + *faces > bytes / 2)
    throw FormatError(path, vertices_at,
                      "the OFF header declares " + std::to_string(*vertices) + " vertices and " + std::to_string(*faces) +
                          " faces, more than the file's " + std::to_string(bytes) + " bytes can hold");
}

}  // namespace

std::vector<Triangle> read_mesh_with_assimp(const std::string& path) {
  check_off_counts(path);
  Assimp::Importer importer;
  const aiScene* scene = importer.ReadFile(path, aiProcess_Triangulate | aiProcess_ValidateDataStructure);
  if (!scene || !scene->mRootNode) throw FormatError(path, std::nullopt, std::string("Assimp: ") + importer.GetErrorString());

  // Every (node, accumulated transform) pair, walked without recursion: a file can
  // nest nodes arbitrarily deep.
  std::vector<std::pair<const aiNode*, Matrix>> placed;
  std::vector<std::pair<const aiNode*, Matrix>> pending{{scene->mRootNode, to_matrix(scene->mRootNode->mTransformation)}};
  std::uint64_t faces = 0;
  while (!pending.empty()) {
    auto [node, matrix] = pending.back();
    pending.pop_back();
    for (unsigned i = 0; i < node->mNumMeshes; ++i) {
      if (node->mMeshes[i] >= scene->mNumMeshes)
        throw FormatError(path, std::nullopt, "a node names mesh " + std::to_string(node->mMeshes[i]) + " of " +
                                                  std::to_string(scene->mNumMeshes));
      faces += scene->mMeshes[node->mMeshes[i]]->mNumFaces;
    }
    if (faces > kMaxMeshTriangles)
      throw InvalidArgument(path + ": the scene places more than " + std::to_string(kMaxMeshTriangles) + " faces");
    if (node->mNumMeshes) placed.emplace_back(node, matrix);
    for (unsigned i = 0; i < node->mNumChildren; ++i)
      pending.emplace_back(node->mChildren[i], multiply(matrix, to_matrix(node->mChildren[i]->mTransformation)));
  }

  // Reserve for what the file holds; instances beyond that grow the vector as they come.
  std::uint64_t stored = 0;
  for (unsigned m = 0; m < scene->mNumMeshes; ++m) stored += scene->mMeshes[m]->mNumFaces;
  std::vector<Triangle> triangles;
  triangles.reserve(std::min(faces, stored));
  for (const auto& [node, matrix] : placed) {
    for (unsigned i = 0; i < node->mNumMeshes; ++i) {
      const aiMesh* mesh = scene->mMeshes[node->mMeshes[i]];
      for (unsigned f = 0; f < mesh->mNumFaces; ++f) {
        const aiFace& face = mesh->mFaces[f];
        // Triangulation leaves points (1), lines (2) and triangles (3); validation
        // refuses empty faces. Anything else is skipped rather than trusted.
        if (face.mNumIndices < 1 || face.mNumIndices > 3) continue;
        Triangle t;
        for (unsigned k = 0; k < 3; ++k) {
          const unsigned index = face.mIndices[std::min(k, face.mNumIndices - 1)];
          if (index >= mesh->mNumVertices)
            throw FormatError(path, std::nullopt, "a face names vertex " + std::to_string(index) + " of " +
                                                      std::to_string(mesh->mNumVertices));
          t[k] = transform(matrix, mesh->mVertices[index]);
        }
        triangles.push_back(t);
      }
    }
  }
  if (triangles.empty()) throw FormatError(path, std::nullopt, "the scene holds no triangles, lines or points");
  return triangles;
}

}  // namespace vola::io

// The plugin's entry points (reader_plugin.hpp).
extern "C" {
const char* vola_plugin_version() { return vola::plugin::kPluginVersion; }
void vola_plugin_read_mesh(const std::string& path, std::vector<vola::io::Triangle>& out,
                           vola::plugin::PluginFailure& failure) {
  vola::plugin::capture_failure(failure, [&] { out = vola::io::read_mesh_with_assimp(path); });
}
}
static_assert(std::is_same_v<decltype(&vola_plugin_read_mesh), vola::io::plugin::ReadMeshEntry>);
