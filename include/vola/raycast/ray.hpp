// A ray in voxel-grid coordinates and what casting it finds.
//
// Voxel (i, j, k) is the cube [i, i+1] x [j, j+1] x [k, k+1]; the tree's grid is
// [0, side]^3. A ray is origin + t * direction for t in [0, t_max]; t is the ray
// parameter (a distance when the direction has unit length).
//
// Which voxels a ray visits (the definition every caster here follows, bit for bit):
// - The ray crosses the plane x = p of axis a at crossing_time(p, origin[a], 1 / direction[a]),
//   computed from the plane itself (never accumulated step by step), so that every
//   implementation gets the same double for the same plane.
// - An axis moves when 1 / direction[a] is finite; its start index is floor(origin)
//   when moving up or not at all, ceil(origin) - 1 when moving down: the voxel the
//   ray is in just after t = 0.
// - Events are the crossing times, in increasing order. At an event every axis that
//   crosses a plane at exactly that time steps together (a ray through an edge or a
//   corner goes diagonally; voxels it only touches along the edge are not visited).
// - A visited voxel's entry time is the event that entered it (0 for the start voxel);
//   its normal is -step of the lowest axis (x, then y, then z) crossing at that event,
//   (0, 0, 0) for the start voxel.
// - The hit is the first visited occupied voxel whose entry time is <= t_max.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <limits>

#include "vola/frame.hpp"
#include "vola/key.hpp"

namespace vola::raycast {

struct Ray {
  Point origin{0, 0, 0};
  Point direction{0, 0, 1};
  double t_max = std::numeric_limits<double>::infinity();
};

struct RayHit {
  Voxel voxel;
  double t = 0.0;                 // entry time (ray parameter) into the voxel
  std::array<int, 3> normal{};    // face crossed to enter, pointing back at the ray
  friend bool operator==(const RayHit&, const RayHit&) = default;
};

// Origins further than this from the grid are rejected: the integer voxel indices and
// the plane differences stay exact well inside it.
inline constexpr double kMaxOriginMagnitude = 1e12;

// Throws InvalidArgument for a non-finite or too distant origin, a zero or non-finite
// direction, or a negative or NaN t_max.
void check_ray(const Ray& ray);

inline double crossing_time(double plane, double origin, double inverse_direction) noexcept {
  return (plane - origin) * inverse_direction;
}

// Per-axis constants of one ray.
struct RayAxes {
  std::array<double, 3> inverse{};   // 1 / direction
  std::array<int, 3> step{};         // +1, -1, or 0 for an axis that does not move
  std::array<std::int64_t, 3> start{};  // the voxel just after t = 0
  explicit RayAxes(const Ray& ray) noexcept {
    for (int a = 0; a < 3; ++a) {
      const double d = ray.direction[a];
      inverse[a] = 1.0 / d;
      step[a] = (d != 0.0 && std::isfinite(inverse[a])) ? (d > 0.0 ? 1 : -1) : 0;
      const double o = ray.origin[a];
      start[a] = static_cast<std::int64_t>(step[a] < 0 ? std::ceil(o) - 1.0 : std::floor(o));
    }
  }
  // The plane through which the ray enters index i (moving axes only).
  double entry_plane(int a, std::int64_t i) const noexcept {
    return static_cast<double>(step[a] > 0 ? i : i + 1);
  }
  // The plane through which the ray leaves index i (moving axes only).
  double exit_plane(int a, std::int64_t i) const noexcept {
    return static_cast<double>(step[a] > 0 ? i + 1 : i);
  }
};

}  // namespace vola::raycast
