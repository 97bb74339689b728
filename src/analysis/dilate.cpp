// Cube: separable, r one-voxel steps per axis. Sphere: the x-dilations by every half
// width 0..r, each shifted by the (dy, dz) offsets of the disc whose x extent is that
// half width: about pi r^2 shifted copies instead of 4/3 pi r^3.
#include <cmath>
#include <string>
#include <vector>

#include "brick_set.hpp"
#include "morphology_steps.hpp"
#include "same_frame.hpp"
#include "vola/analysis/morphology.hpp"
#include "vola/error.hpp"

namespace vola::analysis {

namespace detail {

BrickSet step_along(const BrickSet& in, int axis) {
  BrickSet out(in.depth(), in.blocks() * 2);
  out.add_shifted(in, 0, 0, 0);
  const int d[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  out.add_shifted(in, d[axis][0], d[axis][1], d[axis][2]);
  out.add_shifted(in, -d[axis][0], -d[axis][1], -d[axis][2]);
  return out;
}

BrickSet dilate_bricks(const BrickSet& in, int radius, Element element) {
  if (radius == 0) {
    BrickSet copy(in.depth(), in.blocks());
    copy.add_shifted(in, 0, 0, 0);
    return copy;
  }
  if (element == Element::cube) {
    BrickSet current = step_along(in, 0);
    for (int axis = 0; axis < 3; ++axis)
      for (int i = (axis == 0 ? 1 : 0); i < radius; ++i) current = step_along(current, axis);
    return current;
  }
  std::vector<BrickSet> along_x;  // along_x[h]: dilated by h voxels along x
  along_x.reserve(static_cast<std::size_t>(radius) + 1);
  along_x.push_back(dilate_bricks(in, 0, element));
  for (int h = 1; h <= radius; ++h) along_x.push_back(step_along(along_x.back(), 0));
  BrickSet out(in.depth(), along_x.back().blocks() * 2);
  const long r2 = static_cast<long>(radius) * radius;
  for (int dz = -radius; dz <= radius; ++dz)
    for (int dy = -radius; dy <= radius; ++dy) {
      const long rest = r2 - static_cast<long>(dy) * dy - static_cast<long>(dz) * dz;
      if (rest < 0) continue;
      long h = static_cast<long>(std::sqrt(static_cast<double>(rest)));
      while (h * h > rest) --h;  // exact integer square root
      while ((h + 1) * (h + 1) <= rest) ++h;
      out.add_shifted(along_x[static_cast<std::size_t>(h)], 0, dy, dz);
    }
  return out;
}

void check_radius(const Tree& tree, int radius) {
  if (radius < 0 || static_cast<std::int64_t>(radius) >= std::int64_t{tree.side()})
    throw InvalidArgument("radius " + std::to_string(radius) + " outside 0.." + std::to_string(tree.side() - 1) +
                          " for a depth-" + std::to_string(tree.depth()) + " grid");
}

}  // namespace detail

Tree dilate(const Tree& tree, int radius, Element element) {
  detail::check_radius(tree, radius);
  const detail::BrickSet in = detail::BrickSet::from_tree(tree);
  return detail::with_frame_of(detail::dilate_bricks(in, radius, element).to_tree(), tree);
}

}  // namespace vola::analysis
