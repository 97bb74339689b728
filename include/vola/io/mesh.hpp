// Meshes: OFF and STL (ascii and binary) read by vola (src/io/mesh_files.hpp), OBJ,
// glTF, COLLADA and 3DS through Assimp.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "vola/io/input.hpp"

namespace vola::io {

// A scene may instance its meshes any number of times; refuse to expand it past this.
inline constexpr std::uint64_t kMaxMeshTriangles = std::uint64_t{1} << 27;

// Every face of every mesh the scene's nodes place, with the node transforms applied,
// polygons triangulated. Lines and points become degenerate triangles (a, b, b) and
// (a, a, a), so they still voxelize to what they touch; vertices no face uses are left
// out (they widen no toolkit frame). Assimp stores coordinates as 32-bit floats, STL
// defines them so. Throws FormatError (Assimp's message through Assimp) when it cannot
// read the file, or when the scene holds no geometry; IoError when it cannot open it.
std::vector<Triangle> read_mesh_triangles(const std::string& path);

}  // namespace vola::io
