// Internal to the conversion pipeline: inputs that are not plain points, to trees.
#pragma once

#include "vola/builder.hpp"
#include "vola/io/input.hpp"

namespace vola::convert_detail {

// A voxel-grid input (binvox, NPY occupancy, maps) cell for cell, its per-cell values as
// columns; depth 0 = the smallest that holds it. A map with free cells (an OctoMap's)
// becomes a state map of its occupied and free cells.
Tree tree_from_grid_cells(const io::VoxelGrid& grid, int depth, BuildReport& report);
// The cell centres of a voxel-grid input, as points with its per-cell values (to quantize
// on another grid).
PointCloud grid_cell_centres(const io::VoxelGrid& grid);
// The same for the grid `options` will build: the centres, or, when its voxels are smaller
// than the cells (a binvox read at a finer voxel size), k^3 points a cell, spaced at most
// one voxel apart, so that the voxels a cell covers are all set (centres alone gave walls
// of isolated voxels k apart); a voxel across a cell's face may be set too. Throws InvalidArgument above 2^25 points.
PointCloud grid_cell_points(const io::VoxelGrid& grid, const BuildOptions& options);
// Triangles -> surface voxels (and the inside when solid). Toolkit mode frames the
// vertices' bbox, as a point cloud's bbox frames its points.
Tree tree_from_mesh(const io::Input& input, const BuildOptions& options, bool solid, BuildReport& report);
// DEM cells -> columns of voxels from the base height up to each cell's height; the
// frame covers the base too.
Tree tree_from_terrain(const io::Input& input, const BuildOptions& options, BuildReport& report);

}  // namespace vola::convert_detail
