// Dilation and erosion as one depth-first walk over the input tree's levels, emitting
// the result's levels in key order as it goes: no hash, no sort, no copy of the input.
//
// Every visited output block carries a window of the input's blocks of its level
// around it (index and word of each, from the window one level up: a child is found
// by popcount, never by a lookup from the root). A block of the level above the leaves
// gathers the leaf words of its 4x4x4 bricks and a halo of ceil(r / 4) bricks into a
// small dense array and computes its 64 result bricks there, 64 voxels per word
// operation; a result word that is not zero is appended to its level, and a block's
// own word (which children were not empty) follows its children.
#pragma once

#include "vola/analysis/morphology.hpp"
#include "vola/tree.hpp"

namespace vola::analysis::detail {

enum class Operation { dilate, erode };

// The voxels of `tree` dilated or eroded by the element of radius `radius` (see
// morphology.hpp), as a tree of the same depth without payload, frame or attributes.
// radius must lie in 0 .. side - 1. `progress` (may be empty) hears of the blocks done.
Tree morph(const Tree& tree, Operation operation, int radius, Element element, const MorphProgress& progress);

// Throws InvalidArgument unless 0 <= radius < the grid side.
void check_radius(const Tree& tree, int radius);

}  // namespace vola::analysis::detail
