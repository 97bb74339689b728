// Mesh files -> solid object grids in the npz's convention.
#include <algorithm>

#include "vola/error.hpp"
#include "vola/io/mesh.hpp"
#include "vola/learn/dataset.hpp"
#include "vola/mesh/voxelize.hpp"

namespace vola::learn {

std::vector<std::uint8_t> mesh_object_grid(const std::string& path, int side) {
  if (side < 4 || side > kSceneSide) throw InvalidArgument("object grid side must be 4..64, got " + std::to_string(side));
  const std::vector<mesh::Triangle> triangles = io::read_mesh_triangles(path);
  const Box bounds = mesh::triangle_bounds(triangles);
  double extent = 0;
  for (int a = 0; a < 3; ++a) extent = std::max(extent, bounds.max[a] - bounds.min[a]);
  if (!(extent > 0)) throw FormatError(path, std::nullopt, "the mesh has no extent: nothing to voxelize");
  // The longest extent spans the grid (a hair wider, so that its far face falls in the
  // last cell), centred on every axis.
  const double voxel = extent / side * (1 + 1e-9);
  Point origin;
  for (int a = 0; a < 3; ++a) origin[a] = (bounds.min[a] + bounds.max[a]) / 2 - voxel * side / 2;
  const Tree tree = mesh::voxelize(triangles, Quantizer::grid(origin, voxel, kSceneDepth), {.solid = true});
  std::vector<std::uint8_t> grid(std::size_t(side) * side * side, 0);
  const std::uint32_t s = std::uint32_t(side);
  tree.for_each_voxel([&](const Voxel& v) {
    if (v.x < s && v.y < s && v.z < s) grid[(std::size_t(v.x) * s + v.y) * s + v.z] = 1;
  });
  return grid;
}

}  // namespace vola::learn
