// Connected components of a tree's voxels, computed on the sparse structure: union-find
// over voxels indexed by rank, neighbours found through the leaf blocks (4x4x4 words)
// without expanding the grid.
#pragma once

#include <cstdint>
#include <vector>

#include "vola/frame.hpp"
#include "vola/tree.hpp"

namespace vola::analysis {

// Which voxels touch: 6 = sharing a face, 18 = a face or an edge, 26 = a face, an edge
// or a corner (scipy.ndimage.generate_binary_structure(3, 1 | 2 | 3)).
enum class Connectivity : int { faces = 6, edges = 18, corners = 26 };
// 6, 18 or 26 -> Connectivity; throws InvalidArgument otherwise.
Connectivity parse_connectivity(int neighbours);

struct Component {
  std::uint64_t voxels = 0;
  Voxel min;                          // inclusive voxel bounding box
  Voxel max;
  Point centroid{0, 0, 0};            // mean voxel index per axis (voxel units)
  std::uint64_t first_rank = 0;       // rank of its first voxel in key order
};

struct ComponentLabels {
  // Component of every voxel, indexed by rank; components are numbered 0.. in the
  // order of `components`: by size, largest first, ties by first voxel in key order.
  std::vector<std::uint32_t> label;
  std::vector<Component> components;
};

// Throws InvalidArgument beyond 2^32 - 1 voxels (labels are 32-bit).
ComponentLabels label_components(const Tree& tree, Connectivity connectivity);

}  // namespace vola::analysis
