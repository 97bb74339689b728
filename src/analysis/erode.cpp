// Erosion: the same walk as dilation (morphology_walk.hpp) with AND in place of OR over
// the element's offsets, visiting only the input's own blocks. Cells outside the grid
// are absent from every window, hence empty, so voxels within r of the grid's edge go.
#include "morphology_walk.hpp"
#include "same_frame.hpp"
#include "vola/analysis/morphology.hpp"

namespace vola::analysis {

Tree erode(const Tree& tree, int radius, Element element, const MorphProgress& progress) {
  detail::check_radius(tree, radius);
  return detail::with_frame_of(detail::morph(tree, detail::Operation::erode, radius, element, progress), tree);
}

}  // namespace vola::analysis
