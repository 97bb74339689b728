// Dilation: one walk over the input's levels (morphology_walk.hpp). Cube: separable, x
// then y then z on each block's bricks. Sphere: the x-dilations by every half width
// 0..r, each seen at the (dy, dz) offsets of the disc whose x extent is that half width:
// about pi r^2 shifted words per brick instead of 4/3 pi r^3.
#include <algorithm>
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "morphology_walk.hpp"
#include "same_frame.hpp"
#include "vola/analysis/morphology.hpp"
#include "vola/builder.hpp"
#include "vola/error.hpp"

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

// `tree` on a grid whose faces lie at least `margin` voxels from its voxels: the same
// voxels shifted up by whole voxels where they come near the low faces, the origin moved
// down by as much, the depth raised until the far side has room. Attributes and payloads
// are not kept (the dilation drops them); the frame is grid mode, at the same world place.
Tree with_margin(const Tree& tree, int margin) {
  std::array<std::uint32_t, 3> low{tree.side(), tree.side(), tree.side()}, high{0, 0, 0};
  tree.for_each_voxel([&](const Voxel& v) {
    const std::uint32_t c[3] = {v.x, v.y, v.z};
    for (int a = 0; a < 3; ++a) low[a] = std::min(low[a], c[a]), high[a] = std::max(high[a], c[a]);
  });
  const auto m = static_cast<std::uint64_t>(margin);
  std::array<std::uint64_t, 3> shift{};
  std::uint64_t reach = 0;  // the highest index the result needs
  for (int a = 0; a < 3; ++a) {
    shift[a] = low[a] < m ? m - low[a] : 0;
    reach = std::max(reach, high[a] + shift[a] + m);
  }
  int depth = tree.depth();
  while (depth <= kMaxDepth && side_of(depth) <= reach) ++depth;
  if (shift == std::array<std::uint64_t, 3>{} && depth == tree.depth()) return tree;
  if (depth > kMaxDepth)
    throw InvalidArgument("radius " + std::to_string(margin) + ": the grid grown to hold the whole dilation would " +
                          "need more than depth " + std::to_string(kMaxDepth) +
                          " (4^10 voxels a side); dilate within the grid instead (vola dilate --keep-grid)");
  std::vector<Voxel> moved;
  moved.reserve(tree.voxel_count());
  tree.for_each_voxel([&](const Voxel& v) {
    moved.push_back({static_cast<std::uint32_t>(v.x + shift[0]), static_cast<std::uint32_t>(v.y + shift[1]),
                     static_cast<std::uint32_t>(v.z + shift[2])});
  });
  Tree grown = build_from_voxels(moved, depth);
  Frame frame = tree.frame();
  for (int a = 0; a < 3; ++a) frame.origin[a] -= static_cast<double>(shift[a]) * frame.voxel_size;
  frame.quantization = Quantization::grid;
  grown.georef() = tree.georef();
  grown.set_frame(frame);
  return grown;
}

}  // namespace

Tree dilate_unclipped(const Tree& tree, int radius, Element element, const MorphProgress& progress) {
  if (radius < 0 || tree.empty()) return dilate(tree, radius, element, progress);  // dilate says what is wrong
  return dilate(with_margin(tree, radius), radius, element, progress);
}

Tree dilate(const Tree& tree, int radius, Element element, const MorphProgress& progress) {
  detail::check_radius(tree, radius);
  check_result_size(tree, radius, element);
  return detail::with_frame_of(detail::morph(tree, detail::Operation::dilate, radius, element, progress), tree);
}

}  // namespace vola::analysis
