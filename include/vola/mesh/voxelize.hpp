// Triangles -> voxels: every voxel whose closed cell box a triangle touches (the exact
// separating-axis test of triangle_box.hpp), optionally with the voxels the surface
// encloses (solid.hpp).
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "vola/frame.hpp"
#include "vola/key.hpp"
#include "vola/mesh/solid.hpp"
#include "vola/mesh/triangle_box.hpp"
#include "vola/tree.hpp"

namespace vola::mesh {

struct VoxelizeOptions {
  bool solid = false;                          // add the voxels the surface encloses
  std::uint64_t max_fill_cells = kMaxFillCells;  // solid: refuse bigger bounding boxes
};

struct VoxelizeReport {
  std::uint64_t triangles = 0;        // given
  std::uint64_t skipped = 0;          // a vertex not finite or beyond +-kMaxCoordinate
  std::uint64_t outside = 0;          // grid mode: not touching the grid
  std::uint64_t surface_voxels = 0;
  std::uint64_t enclosed_voxels = 0;  // solid: added inside the surface
};

// Per-axis bounds of the vertices of the usable triangles (a zero box when there are
// none): the bbox a toolkit-mode frame of the mesh is made from.
Box triangle_bounds(std::span<const Triangle> triangles) noexcept;

// The keys, sorted and unique, of every voxel whose quantizer.cell_box() intersects a
// triangle. Triangles that are not usable (TriangleBoxTest::usable) are skipped.
// Work per triangle is proportional to the voxels it touches (plus a few per row of
// voxels it crosses), not to its voxel bounding box.
std::vector<Key> surface_keys(std::span<const Triangle> triangles, const Quantizer& quantizer,
                              VoxelizeReport* report = nullptr);

// The tree of surface_keys (with options.solid: solid_tree of them), with the
// quantizer's frame. Its georef bbox is left to the caller (the bbox the quantizer was
// made from).
Tree voxelize(std::span<const Triangle> triangles, const Quantizer& quantizer, const VoxelizeOptions& options = {},
              VoxelizeReport* report = nullptr);

}  // namespace vola::mesh
