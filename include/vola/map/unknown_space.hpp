// How much of a query a state map has not seen: the unknown voxels (neither free nor
// occupied, or off the map's grid) that a segment, sphere or box reaches. A collision
// query answers "free" for them, as for free space, but OctoMap's ray casts stop there
// and `vola plan` takes them for obstacles, so `vola collide` and Python's collide_*
// report them beside the answer.
//
// Coordinates are grid coordinates (voxel (i, j, k) is the cube [i, i+1] x [j, j+1] x
// [k, k+1]; raycast::world_to_grid converts world points). Each returns nullopt when the
// query reaches more than kMaxUnknownCells cells (not counted, rather than a count of 0),
// and 0 for a tree that is not a state map (it has no unknown space).
#pragma once

#include <cstdint>
#include <optional>

#include "vola/frame.hpp"
#include "vola/tree.hpp"

namespace vola::map {

inline constexpr std::uint64_t kMaxUnknownCells = std::uint64_t{1} << 26;

// The voxels a segment passes through, sampled at a quarter of a voxel.
std::optional<std::uint64_t> unknown_voxels_on_segment(const Tree& states, const Point& from, const Point& to);
// The voxels within `radius` of `centre` (a voxel's cube touching the sphere counts), as
// Collider::sphere decides a hit.
std::optional<std::uint64_t> unknown_voxels_in_sphere(const Tree& states, const Point& centre, double radius);
// The voxels overlapping the box's interior (touching faces do not count), as
// Collider::box decides a hit.
std::optional<std::uint64_t> unknown_voxels_in_box(const Tree& states, const Box& box);

}  // namespace vola::map
