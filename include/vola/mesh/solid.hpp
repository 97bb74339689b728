// The inside of a closed surface of voxels: flood fill of the outside.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "vola/key.hpp"
#include "vola/tree.hpp"

namespace vola::mesh {

// The fill keeps one bit per cell of the surface's bounding box (padded by one cell per
// side): 2^33 cells (a 2048^3 box) = 1 GiB of bits. Bigger boxes are refused.
inline constexpr std::uint64_t kMaxFillCells = std::uint64_t{1} << 33;

// The voxels enclosed by `surface` (keys of one grid, any order, duplicates allowed):
// the cells of the surface's bounding box that no 6-connected path from outside the box
// reaches without stepping on a surface voxel. Surface voxels are not included; an open
// surface encloses nothing. Keys come in x-fastest order, unsorted, 8 bytes each.
// Throws InvalidArgument when the bounding box holds more than `max_cells` cells.
std::vector<Key> enclosed_keys(std::span<const Key> surface, std::uint64_t max_cells = kMaxFillCells);

// The depth-`depth` tree of the surface and every voxel it encloses, built straight
// from the fill's bits: memory is the bits plus the tree, however many voxels are
// enclosed. Same limit as enclosed_keys.
Tree solid_tree(std::span<const Key> surface, int depth, std::uint64_t max_cells = kMaxFillCells);

}  // namespace vola::mesh
