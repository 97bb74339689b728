// Erosion: the same walk as dilation (morphology_walk.hpp) with AND in place of OR over
// the element's offsets, visiting only the input's own blocks. Cells outside the grid
// are absent from every window, hence empty, so voxels within r of the grid's edge go.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <string>

#include "morphology_walk.hpp"
#include "same_frame.hpp"
#include "vola/analysis/morphology.hpp"

namespace vola::analysis {

namespace {

// True when the element fits nowhere, so that nothing is kept: the tree has fewer voxels
// than the element has cells (a cube's (2r + 1)^3; a sphere holds at least the cube of
// half width r / sqrt(3)), or the element (2r + 1 voxels across along each axis, a
// sphere's too) is wider than the voxels' extent along some axis. The walk's windows grow
// with the radius whatever the data (radius 5000 over three voxels took 2.9 GB before
// failing; 1000 took 23 s to give nothing).
bool fits_nowhere(const Tree& tree, int radius, Element element) {
  if (tree.empty()) return true;
  const double half = element == Element::cube ? radius : std::floor(radius / std::sqrt(3.0));
  if (static_cast<double>(tree.voxel_count()) < std::pow(2.0 * half + 1.0, 3)) return true;
  std::array<std::uint32_t, 3> lo{~0u, ~0u, ~0u}, hi{0, 0, 0};
  tree.for_each_voxel([&](const Voxel& v) {
    const std::array<std::uint32_t, 3> c{v.x, v.y, v.z};
    for (int a = 0; a < 3; ++a) lo[a] = std::min(lo[a], c[a]), hi[a] = std::max(hi[a], c[a]);
  });
  for (int a = 0; a < 3; ++a)
    if (std::uint64_t{hi[a]} - lo[a] + 1 < 2 * std::uint64_t(radius) + 1) return true;
  return false;
}

}  // namespace

Tree erode(const Tree& tree, int radius, Element element, const MorphProgress& progress) {
  detail::check_radius(tree, radius);
  if (radius > 0 && fits_nowhere(tree, radius, element)) {
    if (progress) progress(1, 1);
    return detail::with_frame_of(Tree::from_levels(tree.depth(), false, {0}), tree);
  }
  return detail::with_frame_of(detail::morph(tree, detail::Operation::erode, radius, element, progress), tree);
}

}  // namespace vola::analysis
