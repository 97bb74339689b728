// Height fields (DEM cells) -> columns of voxels.
#pragma once

#include <cstdint>

#include "vola/builder.hpp"
#include "vola/frame.hpp"
#include "vola/tree.hpp"

namespace vola::mesh {

// Columns hold at most this many voxels in all; beyond it the caller must ask for the
// surface only or a coarser grid. The tree is built straight from the columns (memory:
// 16 bytes per column plus the tree, about a bit per voxel for columns side by side).
inline constexpr std::uint64_t kMaxColumnVoxels = std::uint64_t{1} << 34;

struct TerrainOptions {
  double base = 0.0;          // world height the columns start from
  bool surface_only = false;  // just the voxel of each cell's height
  std::uint64_t max_voxels = kMaxColumnVoxels;
};

// Each point (a cell centre at its height) becomes the column of voxels between its own
// voxel and the voxel of (x, y, base), both included; a base outside a grid-mode grid
// is clamped to it. Columns of points that share a voxel column merge. Points the
// quantizer refuses are counted in report->points_outside. The tree has the
// quantizer's frame; the georef bbox is left to the caller. Throws InvalidArgument when
// the columns would hold more than options.max_voxels voxels, or when the base is not
// finite (unless surface_only).
Tree terrain_columns(const PointCloud& surface, const Quantizer& quantizer, const TerrainOptions& options,
                     BuildReport* report = nullptr);

}  // namespace vola::mesh
