// Cropping a tree to a box of voxel indices.
#pragma once

#include "vola/tree.hpp"

namespace vola::analysis {

// The voxels with min <= (x, y, z) <= max per axis (inclusive). Keeps depth, frame and
// georeferencing; drops payloads and attributes. A box that misses the grid gives an
// empty tree; one whose max lies below its min on an axis is an InvalidArgument.
Tree crop(const Tree& tree, const Voxel& min, const Voxel& max);

}  // namespace vola::analysis
