// Dilation and erosion of a tree's voxels by a radius, on 4x4x4 bricks (64 voxels per
// word operation) over the occupied region only, in one walk over the tree's levels
// that emits the result's levels as it goes (no hash, no sort). Used by planners to inflate
// obstacles. Results keep the input's depth, frame and georeferencing; payloads and
// attribute columns are dropped (a grown voxel has no measured value).
#pragma once

#include <cstdint>
#include <functional>

#include "vola/tree.hpp"

namespace vola::analysis {

enum class Element {
  sphere,  // offsets with dx^2 + dy^2 + dz^2 <= r^2
  cube,    // offsets with max(|dx|, |dy|, |dz|) <= r
};

// How far a long dilation or erosion is (a radius of tens of voxels over a survey takes
// minutes): `done` of `total`, called from the calling thread every 64 blocks of 16^3 voxels.
using MorphProgress = std::function<void(std::uint64_t done, std::uint64_t total)>;

// The voxels within the element of radius r of an occupied voxel, clipped to the grid.
// r = 0 copies. Throws InvalidArgument for r < 0 or r >= the grid side.
Tree dilate(const Tree& tree, int radius, Element element, const MorphProgress& progress = {});
// dilate without the clipping: where the voxels come within r of the grid's faces, the
// result's grid is grown first (its origin moved down by whole voxels, its depth raised
// when the far side needs room), so every voxel within r of an occupied one is there,
// at the same world place. A grid-mode file's origin sat on its data's minimum, so a
// clipped dilation lost the inflation below every map (and `collide` found the inflated
// map free where the map itself was hit). The result is grid-quantized. Throws
// InvalidArgument when the grown grid would need more than depth 10 (dilate clips).
Tree dilate_unclipped(const Tree& tree, int radius, Element element, const MorphProgress& progress = {});
// The voxels whose whole element of radius r is occupied; cells outside the grid
// count as empty (scipy.ndimage.binary_erosion's border_value = 0), so voxels within r
// of the grid's edge are removed. Computed on the input's own bricks (AND over the
// element's offsets), without complementing the grid.
Tree erode(const Tree& tree, int radius, Element element, const MorphProgress& progress = {});

}  // namespace vola::analysis
