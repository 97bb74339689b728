// Collision queries against the occupied voxels, in voxel-grid coordinates (voxel
// (i, j, k) is the closed cube [i, i+1] x [j, j+1] x [k, k+1]):
//   segment: the first voxel the segment a -> b visits (the ray rules of ray.hpp, t in [0, 1]);
//            a segment of no length (a == b) is its point: the voxel holding it, at t = 0;
//   sphere:  is any voxel within distance <= radius of the centre (touching counts);
//   box:     does any voxel's interior overlap the box's interior (touching faces do not count).
// Sphere and box descend the tree only into nodes whose cube passes the same test.
#pragma once

#include <optional>
#include <vector>

#include "vola/frame.hpp"
#include "vola/raycast/ray_caster.hpp"

namespace vola::raycast {

class Collider {
 public:
  // The tree must outlive the collider.
  explicit Collider(const Tree& tree);

  // Throws InvalidArgument when a == b or a point is not finite.
  std::optional<RayHit> segment(const Point& a, const Point& b) const;
  // Throws InvalidArgument for a non-finite centre or a negative/NaN radius.
  bool sphere(const Point& centre, double radius) const;
  // Throws InvalidArgument for a non-finite box or min > max on an axis.
  bool box(const Box& box) const;

  const Tree& tree() const noexcept { return caster_.tree(); }
  const RayCaster& caster() const noexcept { return caster_; }

 private:
  template <class Overlaps>
  bool any_voxel(int level, std::size_t block, const Voxel& origin, const Overlaps& overlaps) const;

  RayCaster caster_;
  std::vector<RankDirectory> rank_;
};

}  // namespace vola::raycast
