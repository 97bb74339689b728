// What a fused TSDF map becomes: a VOLA tree of its surface voxels (with colour), a
// triangle mesh by marching cubes, and memory figures against a dense grid.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "vola/slam/tsdf_store.hpp"
#include "vola/tree.hpp"

namespace vola::slam {

struct SurfaceVoxel {
  std::uint32_t x = 0, y = 0, z = 0;  // volume grid coordinates
  std::uint8_t r = 0, g = 0, b = 0;
};

// Observed voxels at the zero crossing: a voxel whose TSDF sign differs from an observed
// face neighbour's and whose |TSDF| is not larger than that neighbour's (one voxel
// layer per surface). Sorted by (z, y, x).
template <class Store>
std::vector<SurfaceVoxel> surface_voxels(const Store& store);

// A grid-mode tree of the surface voxels in world coordinates (voxel size and a grid
// origin on the volume's grid), with u8 red/green/blue columns when with_colour.
Tree surface_tree(const std::vector<SurfaceVoxel>& voxels, const VolumeGeometry& geometry, bool with_colour);

struct Mesh {
  std::vector<std::array<float, 3>> vertices;
  std::vector<std::array<std::uint8_t, 3>> colours;  // one per vertex
  std::vector<std::array<std::uint32_t, 3>> triangles;  // counter-clockwise seen from the free side
};

// Marching cubes over the cubes between observed voxel centres whose TSDF values all lie
// inside the truncation band; vertices are shared between neighbouring cubes. The case
// table is derived at start-up from the cube's faces (ambiguous faces separate the
// inside corners), so cubes meeting at a face always agree on its segments.
template <class Store>
Mesh marching_cubes(const Store& store);

// The case table: for each of the 256 inside-corner masks, triangles as triples of cube
// edges (edge e joins corners kEdgeCorners[e]). Exposed for tests.
const std::vector<std::vector<std::array<int, 3>>>& marching_cubes_table();
extern const std::array<std::array<int, 2>, 12> kEdgeCorners;

// Binary little-endian PLY; colours written when with_colour. The vertices are moved by
// `origin` (the map's place in the world, FuseResult::origin) and written as doubles when
// it is not 0: floats keep only about half a metre at survey coordinates. Throws IoError.
void write_ply(const std::string& path, const Mesh& mesh, bool with_colour,
               const Eigen::Vector3d& origin = Eigen::Vector3d::Zero());

struct MapMemory {
  std::size_t sparse_bytes = 0;     // the sparse store as it is
  std::size_t dense_bytes = 0;      // a dense grid of the same voxel size over the allocated bricks' bounding box
  std::size_t bricks = 0;
  std::array<std::uint32_t, 3> extent_voxels{};  // that bounding box in voxels
};
MapMemory map_memory(const SparseTsdfStore& store);

}  // namespace vola::slam
