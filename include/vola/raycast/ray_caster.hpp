// Hierarchical DDA over a VOLA tree: Amanatides-Woo at every level, descending only
// into occupied nodes and stepping over an empty node at the coarsest level that is
// empty. It finds exactly what reference_cast (reference_dda.hpp) finds: the same voxel,
// entry time and normal, because it crosses the same planes with the same arithmetic
// (ray.hpp) and only skips events inside empty nodes.
//
// The caster keeps, per level, each word next to the index of its first child (so a
// descent is one load and one popcount per level) and, per ray, the path of blocks from
// the root, so a step re-descends only from the first level whose cell changed. Inside
// an occupied 4x4x4 block it steps voxel by voxel testing bits of the block's word,
// until the ray leaves the block.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <vector>

#include "vola/raycast/ray.hpp"
#include "vola/tree.hpp"

namespace vola::raycast {

class RayCaster {
 public:
  // The tree must outlive the caster.
  explicit RayCaster(const Tree& tree);

  std::optional<RayHit> cast(const Ray& ray) const;
  // hits[i] = cast(rays[i]), on `threads` threads (0 = vola::thread_count()).
  void cast(std::span<const Ray> rays, std::span<std::optional<RayHit>> hits, unsigned threads = 0) const;

  const Tree& tree() const noexcept { return *tree_; }

 private:
  struct Node {
    std::uint64_t bits;         // the occupancy word
    std::uint64_t first_child;  // index in nodes_ of its first child block
  };
  struct Level;  // the ray's state at one level of the tree (ray_caster.cpp)
  // The walk after clipping, from voxel v at time t, for a direction whose per-axis
  // signs (+1, -1, 0) are X, Y, Z: compile-time signs fold the per-axis choices away.
  template <int X, int Y, int Z>
  std::optional<RayHit> walk(const Ray& ray, const RayAxes& axes, const std::array<std::int64_t, 3>& v,
                             double t) const;

  const Tree* tree_;
  std::vector<Node> nodes_;  // every level's blocks, level 0 first
};

// Rays per chunk of the parallel loops over rays and pixels (vola::parallel_for): a chunk
// takes tens of microseconds or more, so handing it out costs next to nothing.
inline constexpr std::size_t kRaysPerChunk = 256;

}  // namespace vola::raycast
