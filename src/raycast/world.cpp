#include "vola/raycast/world.hpp"

namespace vola::raycast {

Point world_to_grid(const Frame& frame, const Point& world) noexcept {
  return {(world[0] - frame.origin[0]) / frame.voxel_size, (world[1] - frame.origin[1]) / frame.voxel_size,
          (world[2] - frame.origin[2]) / frame.voxel_size};
}

Point grid_to_world(const Frame& frame, const Point& grid) noexcept {
  return {frame.origin[0] + grid[0] * frame.voxel_size, frame.origin[1] + grid[1] * frame.voxel_size,
          frame.origin[2] + grid[2] * frame.voxel_size};
}

Ray world_ray_to_grid(const Frame& frame, const Ray& world_ray) noexcept {
  // The same direction in grid space moves voxel_size times faster, so the grid
  // parameter is the world parameter / voxel_size.
  return Ray{world_to_grid(frame, world_ray.origin), world_ray.direction, world_ray.t_max / frame.voxel_size};
}

PinholeCamera world_camera_to_grid(const Frame& frame, const PinholeCamera& world_camera) noexcept {
  PinholeCamera c = world_camera;
  c.eye = world_to_grid(frame, world_camera.eye);
  c.look_at = world_to_grid(frame, world_camera.look_at);
  return c;
}

}  // namespace vola::raycast
