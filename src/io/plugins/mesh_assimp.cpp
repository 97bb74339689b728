#include <algorithm>
#include <array>
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

}  // namespace

std::vector<Triangle> read_mesh_with_assimp(const std::string& path) {
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
