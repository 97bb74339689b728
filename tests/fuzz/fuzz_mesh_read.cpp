// Fuzz entry point of the mesh reader through Assimp (io::read_mesh_with_assimp, what the
// Assimp plugin runs, compiled into this program): the first byte picks the file kind
// (STL, OBJ, OFF, COLLADA, glTF: modulo 5; vola reads PLY itself, not through Assimp), the rest is the file, written to a scratch file
// with that extension. Only vola::Error may escape; what parses must hold at least one
// and at most kMaxMeshTriangles triangles.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <span>

#include "fuzz_seeds.hpp"
#include "scratch_file.hpp"
#include "vola/error.hpp"
#include "readers.hpp"  // src/io/plugins: the reader itself, not its plugin
#include "vola/io/mesh.hpp"

namespace vola_fuzz {
// The extension of each selector value (fuzz_mesh_read_seeds.cpp writes seeds with it).
extern const char* const kMeshExtensions[5];
const char* const kMeshExtensions[5] = {"stl", "obj", "off", "dae", "gltf"};
}  // namespace vola_fuzz

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const std::string path =
      vola_fuzz::scratch_file("mesh", vola_fuzz::kMeshExtensions[data[0] % 5], std::span(data + 1, size - 1));
  try {
    const auto triangles = vola::io::read_mesh_with_assimp(path);
    if (triangles.empty() || triangles.size() > vola::io::kMaxMeshTriangles) std::abort();
  } catch (const vola::Error&) {
    ++vola_fuzz::stats().refused;
    return 0;
  }
  ++vola_fuzz::stats().parsed;
  return 0;
}
