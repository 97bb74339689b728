// Dilation: one walk over the input's levels (morphology_walk.hpp). Cube: separable, x
// then y then z on each block's bricks. Sphere: the x-dilations by every half width
// 0..r, each seen at the (dy, dz) offsets of the disc whose x extent is that half width:
// about pi r^2 shifted words per brick instead of 4/3 pi r^3.
#include "morphology_walk.hpp"
#include "same_frame.hpp"
#include "vola/analysis/morphology.hpp"

namespace vola::analysis {

Tree dilate(const Tree& tree, int radius, Element element, const MorphProgress& progress) {
  detail::check_radius(tree, radius);
  return detail::with_frame_of(detail::morph(tree, detail::Operation::dilate, radius, element, progress), tree);
}

}  // namespace vola::analysis
