// Network input straight from the VOLA bits: a tree's voxels written into a dense
// float grid (the tensor's memory), optionally turned about the vertical axis.
#pragma once

#include <span>

#include "vola/tree.hpp"

namespace vola::learn {

// Zeroes `out` (out_side^3 floats, cell (x, y, z) at (x * out_side + y) * out_side + z)
// and sets to 1 every cell a voxel of `tree` falls in: voxel v of a side-N tree falls
// in cell floor(v * out_side / N) (a 64^3 tree into 32^3 is a 2x2x2 "any"). With an
// angle, each voxel centre is first turned by `angle_radians` about the z axis through
// the grid's centre and rounded down to a voxel; voxels turned out of the grid are
// dropped. Visits voxels with Tree::for_each_voxel: work is per voxel, not per cell.
// Throws InvalidArgument when out is not out_side^3 or out_side exceeds the tree side.
void fill_occupancy(const Tree& tree, int out_side, double angle_radians, std::span<float> out);

}  // namespace vola::learn
