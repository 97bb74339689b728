// erode(A) = A minus dilate(dilate(A) minus A), minus the voxels within r of the grid's
// edge. For a symmetric element, a voxel of A loses exactly when one of its element's
// cells is empty; every such empty cell inside the grid is within r of A, hence in
// dilate(A) minus A, and the voxel is within r of it.
#include "brick_set.hpp"
#include "morphology_steps.hpp"
#include "same_frame.hpp"
#include "vola/analysis/morphology.hpp"

namespace vola::analysis {

namespace {

// Bits of a brick whose coordinate along each axis lies in [lo, hi] (brick origin o).
std::uint64_t inside_mask(std::int64_t ox, std::int64_t oy, std::int64_t oz, std::int64_t lo, std::int64_t hi) {
  std::uint64_t m = 0;
  for (unsigned b = 0; b < 64; ++b) {
    const std::int64_t x = ox + (b & 3u), y = oy + ((b >> 2) & 3u), z = oz + (b >> 4);
    if (x >= lo && x <= hi && y >= lo && y <= hi && z >= lo && z <= hi) m |= std::uint64_t{1} << b;
  }
  return m;
}

}  // namespace

Tree erode(const Tree& tree, int radius, Element element) {
  detail::check_radius(tree, radius);
  const detail::BrickSet a = detail::BrickSet::from_tree(tree);
  const detail::BrickSet grown = detail::dilate_bricks(a, radius, element);
  detail::BrickSet rim(tree.depth(), grown.blocks());  // empty cells within r of A
  grown.for_each([&](std::int64_t bx, std::int64_t by, std::int64_t bz, std::uint64_t w) {
    rim.add(bx, by, bz, w & ~a.get(bx, by, bz));
  });
  const detail::BrickSet lost = detail::dilate_bricks(rim, radius, element);
  const std::int64_t lo = radius, hi = std::int64_t{tree.side()} - 1 - radius;
  detail::BrickSet kept(tree.depth(), a.blocks());
  a.for_each([&](std::int64_t bx, std::int64_t by, std::int64_t bz, std::uint64_t w) {
    std::uint64_t keep = w & ~lost.get(bx, by, bz);
    const std::int64_t ox = bx * 4, oy = by * 4, oz = bz * 4;
    const bool whole_inside = ox >= lo && oy >= lo && oz >= lo && ox + 3 <= hi && oy + 3 <= hi && oz + 3 <= hi;
    if (!whole_inside) keep &= inside_mask(ox, oy, oz, lo, hi);
    kept.add(bx, by, bz, keep);
  });
  return detail::with_frame_of(kept.to_tree(), tree);
}

}  // namespace vola::analysis
