// Rays and cameras in world coordinates, through the tree's frame (origin + voxel
// size): grid = (world - origin) / voxel_size. Directions keep their orientation, so a
// unit grid-space direction gives distances t in voxels; world distance = t * voxel_size.
#pragma once

#include "vola/frame.hpp"
#include "vola/raycast/camera.hpp"
#include "vola/raycast/ray.hpp"

namespace vola::raycast {

Point world_to_grid(const Frame& frame, const Point& world) noexcept;
Point grid_to_world(const Frame& frame, const Point& grid) noexcept;
// The grid ray has the same direction; its parameter t is the world one / voxel_size.
Ray world_ray_to_grid(const Frame& frame, const Ray& world_ray) noexcept;
PinholeCamera world_camera_to_grid(const Frame& frame, const PinholeCamera& world_camera) noexcept;

}  // namespace vola::raycast
