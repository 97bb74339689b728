#include <assimp/BaseImporter.h>
#include <assimp/DefaultIOSystem.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <algorithm>
#include <array>
#include <assimp/Importer.hpp>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string_view>
#include <utility>
#include <vector>

#include "../reader_plugin.hpp"
#include "gltf_draco.hpp"
#include "readers.hpp"
#include "vola/error.hpp"
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

// The extensions of the mesh formats vola documents (input.cpp's format table) that
// Assimp reads here (vola reads PLY, OFF and STL itself). Assimp reads some forty
// formats, chosen by extension and then by content; the others (some with references
// to further files, most never fuzzed here) are not opened.
constexpr std::array<std::string_view, 5> kMeshExtensions = {".obj", ".gltf", ".glb", ".dae", ".3ds"};

std::string lowercase_extension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

void check_mesh_extension(const std::string& path) {
  const std::string ext = lowercase_extension(path);
  if (std::find(kMeshExtensions.begin(), kMeshExtensions.end(), ext) == kMeshExtensions.end())
    throw FormatError(path, std::nullopt,
                      "meshes are read from .stl, .off, .obj, .gltf, .glb, .dae and .3ds files only (and .ply as "
                      "points and faces), not '" +
                          ext + "'");
}

// Assimp opens whatever files a scene names: a glTF buffer's URI (an absolute path, a
// "../" path, a FIFO that blocks forever, a 500 MB library read whole into memory) and an
// OBJ's `mtllib`. vola reads the file it is given and nothing else (docs/SECURITY.md), so
// the importer sees every other path as absent; the first one asked for is kept for the
// error. A missing material file is only a warning to Assimp; a missing glTF buffer fails
// the import.
class ConfinedIOSystem : public Assimp::DefaultIOSystem {
 public:
  explicit ConfinedIOSystem(std::filesystem::path input) : input_(std::move(input)) {}

  bool Exists(const char* file) const override { return allowed(file) && DefaultIOSystem::Exists(file); }

  Assimp::IOStream* Open(const char* file, const char* mode) override {
    return allowed(file) ? DefaultIOSystem::Open(file, mode) : nullptr;
  }

  // The first other file the scene named ("" when none).
  const std::string& refused() const noexcept { return refused_; }

 private:
  bool allowed(const char* file) const {
    std::error_code error;
    if (file && std::filesystem::is_regular_file(file, error) && std::filesystem::equivalent(file, input_, error))
      return true;
    if (refused_.empty()) refused_ = file ? file : "";
    return false;
  }

  std::filesystem::path input_;
  mutable std::string refused_;
};

// What Assimp's validation checks of the parts read below: every mesh, vertex array,
// face array and index array that a count says is there, and the node tree's arrays.
bool structurally_sound(const aiScene& scene) {
  if (!scene.mRootNode || (scene.mNumMeshes && !scene.mMeshes)) return false;
  for (unsigned m = 0; m < scene.mNumMeshes; ++m) {
    const aiMesh* mesh = scene.mMeshes[m];
    if (!mesh || (mesh->mNumVertices && !mesh->mVertices) || (mesh->mNumFaces && !mesh->mFaces)) return false;
    for (unsigned f = 0; f < mesh->mNumFaces; ++f)
      if (mesh->mFaces[f].mNumIndices && !mesh->mFaces[f].mIndices) return false;
  }
  std::vector<const aiNode*> pending{scene.mRootNode};
  std::uint64_t nodes = 0;
  while (!pending.empty()) {
    const aiNode* node = pending.back();
    pending.pop_back();
    if (++nodes > (std::uint64_t{1} << 26) || (node->mNumMeshes && !node->mMeshes) || (node->mNumChildren && !node->mChildren))
      return false;
    for (unsigned i = 0; i < node->mNumChildren; ++i) {
      if (!node->mChildren[i]) return false;
      pending.push_back(node->mChildren[i]);
    }
  }
  return true;
}

// Assimp falls back to any importer whose signature matches when the one of the file's
// extension refuses it: fuzz_mesh_read found a .gltf beginning "quick3ds" sent to the
// Quick3D importer, which asked for 1.5 TB. Only the importers of `extension` (no dot)
// are left registered, so nothing else reads the file.
void keep_only_importers_of(Assimp::Importer& importer, const std::string& extension) {
  for (std::size_t i = importer.GetImporterCount(); i-- > 0;) {
    const aiImporterDesc* info = importer.GetImporterInfo(i);
    std::istringstream extensions(info && info->mFileExtensions ? info->mFileExtensions : "");
    bool claims = false;
    for (std::string e; extensions >> e;) claims = claims || e == extension;
    if (claims) continue;
    Assimp::BaseImporter* other = importer.GetImporter(i);
    if (importer.UnregisterLoader(other) == aiReturn_SUCCESS) delete other;  // the importer owns only those registered
  }
}

std::optional<std::string> decoded_draco_scene(const std::string& path) {
  const std::string ext = lowercase_extension(path);
  if (ext != ".gltf" && ext != ".glb") return std::nullopt;
  std::ifstream in(path, std::ios::binary);
  std::ostringstream whole;
  whole << in.rdbuf();
  if (!in) throw IoError("cannot read " + path);
  return gltf_with_draco_decoded(path, std::move(whole).str());
}

}  // namespace

std::vector<Triangle> read_mesh_with_assimp(const std::string& path) {
  check_mesh_extension(path);
  // A glTF with Draco-compressed primitives goes to Assimp with them decoded (gltf_draco.hpp).
  const std::optional<std::string> draco_decoded = decoded_draco_scene(path);
  Assimp::Importer importer;
  keep_only_importers_of(importer, draco_decoded ? "glb" : lowercase_extension(path).substr(1));
  auto* io = new ConfinedIOSystem(path);
  importer.SetIOHandler(io);  // the importer owns it
  const auto import = [&](unsigned flags) {
    return draco_decoded ? importer.ReadFileFromMemory(draco_decoded->data(), draco_decoded->size(), flags, "glb")
                         : importer.ReadFile(path, flags);
  };
  const aiScene* scene = import(aiProcess_Triangulate | aiProcess_ValidateDataStructure);
  // Assimp's validation refuses two things that do not matter here. Its OBJ importer
  // (5.2) can label a mesh's primitive types wrongly (trimesh's cubevt.obj, a textured
  // cube of triangles: "mFaces[0] is a POINT but mPrimitiveTypes does not report the POINT
  // flag"), and a mesh may be empty (an ASCII STL with an empty "solid ... endsolid" beside
  // the real one, as CAD exporters write for an empty body: "The mesh emptySolid contains
  // no vertices"). Neither the flags nor an empty mesh are used, so such a scene is read
  // again without the validation and held to the structural checks the validation would
  // have made (structurally_sound below).
  const auto harmless = [](const std::string& refusal) {
    return refusal.find("mPrimitiveTypes does not report") != std::string::npos ||
           refusal.find("contains no vertices") != std::string::npos;
  };
  if (!scene && harmless(importer.GetErrorString())) {
    const std::string refusal = importer.GetErrorString();
    scene = import(aiProcess_Triangulate);
    if (scene && !structurally_sound(*scene)) throw FormatError(path, std::nullopt, "Assimp: " + refusal);
  }
  // A missing material library is only a warning to Assimp: it is not why a scene failed.
  if (!scene && !io->refused().empty() && lowercase_extension(io->refused()) != ".mtl")
    throw FormatError(path, std::nullopt,
                      "the scene's data lies in another file, '" + io->refused() +
                          "', and vola reads only the file it is given (a glTF with its buffers embedded, "
                          "such as a .glb, holds everything)");
  // Assimp's validation refuses a mesh of vertices alone: an OBJ point cloud ("v" lines,
  // no faces, as CloudCompare and scanners write them). Such a file is read again without
  // it and taken only when no mesh has a face; its vertices are then points (degenerate
  // triangles, as points inside meshes are).
  const bool points_only = !scene && std::string(importer.GetErrorString()).find("contains no faces") != std::string::npos;
  if (points_only) {
    const std::string refusal = importer.GetErrorString();
    scene = import(0);
    const auto vertices_alone = [](const aiScene* s) {
      for (unsigned m = 0; m < s->mNumMeshes; ++m)
        if (!s->mMeshes[m] || s->mMeshes[m]->mNumFaces != 0 || (s->mMeshes[m]->mNumVertices && !s->mMeshes[m]->mVertices))
          return false;
      return s->mMeshes || s->mNumMeshes == 0;
    };
    if (!scene || !scene->mRootNode || !vertices_alone(scene))
      throw FormatError(path, std::nullopt, "Assimp: " + refusal);
  }
  if (!scene || !scene->mRootNode) throw FormatError(path, std::nullopt, std::string("Assimp: ") + importer.GetErrorString());
  const auto elements = [&](const aiMesh* mesh) -> std::uint64_t { return points_only ? mesh->mNumVertices : mesh->mNumFaces; };

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
      faces += elements(scene->mMeshes[node->mMeshes[i]]);
    }
    if (faces > kMaxMeshTriangles)
      throw InvalidArgument(path + ": the scene places more than " + std::to_string(kMaxMeshTriangles) + " faces");
    if (node->mNumMeshes) placed.emplace_back(node, matrix);
    for (unsigned i = 0; i < node->mNumChildren; ++i)
      pending.emplace_back(node->mChildren[i], multiply(matrix, to_matrix(node->mChildren[i]->mTransformation)));
  }

  // Reserve for what the file holds; instances beyond that grow the vector as they come.
  std::uint64_t stored = 0;
  for (unsigned m = 0; m < scene->mNumMeshes; ++m) stored += elements(scene->mMeshes[m]);
  std::vector<Triangle> triangles;
  triangles.reserve(std::min(faces, stored));
  for (const auto& [node, matrix] : placed) {
    for (unsigned i = 0; i < node->mNumMeshes; ++i) {
      const aiMesh* mesh = scene->mMeshes[node->mMeshes[i]];
      if (points_only) {
        for (unsigned v = 0; v < mesh->mNumVertices; ++v) {
          const Point p = transform(matrix, mesh->mVertices[v]);
          triangles.push_back(Triangle{p, p, p});
        }
        continue;
      }
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
