// Fuzz entry point of the mesh readers: the first byte picks the file kind (STL, OBJ,
// OFF, COLLADA, glTF: modulo 5; vola reads PLY itself), the rest is the file. OFF and
// STL go to vola's own readers (io::parse_off, io::parse_stl), the others through Assimp
// (io::read_mesh_with_assimp, what the Assimp plugin runs, compiled into this program),
// from a scratch file with that extension. Only vola::Error may escape; what parses must
// hold at least one and at most kMaxMeshTriangles triangles.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <span>
#include <vector>

#include "fuzz_seeds.hpp"
#include "mesh_files.hpp"  // src/io: the OFF and STL readers
#include "readers.hpp"     // src/io/plugins: the reader itself, not its plugin
#include "scratch_file.hpp"
#include "vola/error.hpp"
#include "vola/io/mesh.hpp"

namespace vola_fuzz {
// The extension of each selector value (fuzz_mesh_read_seeds.cpp writes seeds with it).
extern const char* const kMeshExtensions[5];
const char* const kMeshExtensions[5] = {"stl", "obj", "off", "dae", "gltf"};
}  // namespace vola_fuzz

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const int kind = data[0] % 5;
  const std::span<const std::uint8_t> file(data + 1, size - 1);
  try {
    std::vector<vola::io::Triangle> triangles;
    if (kind == 0)
      triangles = vola::io::parse_stl(file, "fuzz.stl");
    else if (kind == 2)
      triangles = vola::io::parse_off(file, "fuzz.off");
    else
      triangles =
          vola::io::read_mesh_with_assimp(vola_fuzz::scratch_file("mesh", vola_fuzz::kMeshExtensions[kind], file));
    if (triangles.empty() || triangles.size() > vola::io::kMaxMeshTriangles) std::abort();
  } catch (const vola::Error&) {
    ++vola_fuzz::stats().refused;
    return 0;
  }
  ++vola_fuzz::stats().parsed;
  return 0;
}
