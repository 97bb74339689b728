// The inside of a closed surface of voxels: flood fill of the outside.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "vola/key.hpp"

namespace vola::mesh {

// The fill keeps one bit per cell of the surface's bounding box (padded by one cell per
// side); 2^30 cells = a full depth-5 grid (1024^3) = 128 MiB of bits. The voxels it
// returns cost 8 bytes each on top, which is what bounds the default.
inline constexpr std::uint64_t kMaxFillCells = std::uint64_t{1} << 30;

// The voxels enclosed by `surface` (keys of a depth-`depth` grid, any order, duplicates
// allowed): the cells of the surface's bounding box that no 6-connected path from
// outside the box reaches without stepping on a surface voxel. Surface voxels are not
// included; an open surface encloses nothing. Keys come in x-fastest order, unsorted.
// Throws InvalidArgument when the bounding box holds more than `max_cells` cells.
std::vector<Key> enclosed_keys(std::span<const Key> surface, std::uint64_t max_cells = kMaxFillCells);

}  // namespace vola::mesh
