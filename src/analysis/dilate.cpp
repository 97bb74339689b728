// Dilation: one walk over the input's levels (morphology_walk.hpp). Cube: separable, x
// then y then z on each block's bricks. Sphere: the x-dilations by every half width
// 0..r, each seen at the (dy, dz) offsets of the disc whose x extent is that half width:
// about pi r^2 shifted words per brick instead of 4/3 pi r^3.
#include <algorithm>
#include <cstdint>
#include <string>

#include "morphology_walk.hpp"
#include "same_frame.hpp"
#include "vola/analysis/morphology.hpp"

namespace vola::analysis {

namespace {

// A result that no machine here could hold is refused before the walk: it holds at least
// the element around one voxel, clipped to the grid, which is smallest at a corner
// (min(r + 1, side) cells per axis; a sphere at least half of that cube). 2^36 voxels are
// 8 GiB of leaf words even packed densely. (Three voxels dilated by a cube of radius 10^6
// ran for minutes; by 10^5, "out of memory".)
constexpr double kMaxResultVoxels = 68719476736.0;  // 2^36

void check_result_size(const Tree& tree, int radius, Element element) {
  if (tree.empty()) return;
  const double per_axis = std::min(double(radius) + 1.0, double(tree.side()));
  const double least = (element == Element::sphere ? 0.5 : 1.0) * per_axis * per_axis * per_axis;
  if (least > kMaxResultVoxels)
    throw InvalidArgument("radius " + std::to_string(radius) + ": the dilation would hold at least " +
                          std::to_string(static_cast<std::uint64_t>(least)) + " voxels (more than 2^36, 8 GiB of " +
                          "leaf words however packed); give a smaller radius, or dilate a coarser level (vola lod)");
}

}  // namespace

Tree dilate(const Tree& tree, int radius, Element element, const MorphProgress& progress) {
  detail::check_radius(tree, radius);
  check_result_size(tree, radius, element);
  return detail::with_frame_of(detail::morph(tree, detail::Operation::dilate, radius, element, progress), tree);
}

}  // namespace vola::analysis
