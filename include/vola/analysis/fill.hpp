// Filling enclosed cavities: every empty cell that the outside cannot reach through
// face-adjacent empty cells becomes occupied (scipy.ndimage.binary_fill_holes). The
// outside is everything beyond the occupied voxels' bounding box, so the work and the
// memory (2 bits per cell) follow that box, not the grid.
#pragma once

#include <cstdint>

#include "vola/tree.hpp"

namespace vola::analysis {

// Refused (InvalidArgument) when the bounding box grown by one cell per side has more
// cells than this: 2^33 cells = 2 GiB of bits.
inline constexpr std::uint64_t kMaxFillCells = std::uint64_t{1} << 33;

struct FillReport {
  std::uint64_t filled = 0;  // cavity cells that became voxels
};

// Keeps depth, frame and georeferencing; drops payloads and attributes.
Tree fill_cavities(const Tree& tree, FillReport* report = nullptr);

}  // namespace vola::analysis
