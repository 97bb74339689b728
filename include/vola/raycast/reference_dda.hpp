// The obviously right caster: Amanatides-Woo voxel by voxel over the finest grid,
// following the definition in ray.hpp, asking the tree about every voxel. It walks the
// unbounded integer grid from the origin (no clipping code to get wrong) and stops when
// the ray has left the grid's cube moving away from it, or passed t_max.
// It is the reference the hierarchical caster is tested against; slow on purpose.
#pragma once

#include <optional>

#include "vola/raycast/ray.hpp"
#include "vola/tree.hpp"

namespace vola::raycast {

std::optional<RayHit> reference_cast(const Tree& tree, const Ray& ray);

}  // namespace vola::raycast
