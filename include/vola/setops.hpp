// Union, intersection and difference of two trees of equal depth and frame: merges of
// their sorted key lists, O(voxels). The result keeps the first tree's georeferencing
// and frame; payloads and attribute columns are not carried (occupancy only).
// Two grids of one voxel size whose origins differ by whole voxels are one lattice (maps
// from separate `vola map` runs: their origins follow their data): their voxels are
// moved to the lower origin, on the smallest depth at or above both that holds them, and
// the result has that origin and depth (their depths may differ then).
#pragma once

#include "vola/tree.hpp"
#include "vola/version.hpp"

namespace vola {
VOLA_INLINE_NAMESPACE_BEGIN

enum class FrameCheck { require_equal, ignore };

// Throws InvalidArgument when depths differ, or frames differ under require_equal, and
// the trees are not on one lattice as above.
Tree unite(const Tree& a, const Tree& b, FrameCheck check = FrameCheck::require_equal);
Tree intersect(const Tree& a, const Tree& b, FrameCheck check = FrameCheck::require_equal);
Tree subtract(const Tree& a, const Tree& b, FrameCheck check = FrameCheck::require_equal);

VOLA_INLINE_NAMESPACE_END
}  // namespace vola
