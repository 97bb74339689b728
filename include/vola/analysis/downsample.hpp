// Resampling to a coarser depth with a fill threshold.
#pragma once

#include <cstdint>

#include "vola/tree.hpp"

namespace vola::analysis {

// Each depth-`depth` cell becomes a voxel when at least `min_voxels` of this tree's
// voxels lie in it (1 = any: the same voxels as Tree::level_of_detail). The frame's
// voxel size grows by 4 per level dropped; payloads and attributes are dropped.
// Throws InvalidArgument unless 1 <= depth <= tree.depth() and min_voxels >= 1.
Tree downsample(const Tree& tree, int depth, std::uint64_t min_voxels = 1);

}  // namespace vola::analysis
