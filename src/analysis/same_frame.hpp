// Results of an analysis live in their input's world: same georeferencing and grid.
#pragma once

#include "vola/tree.hpp"

namespace vola::analysis::detail {

inline Tree with_frame_of(Tree result, const Tree& source) {
  result.georef() = source.georef();
  if (source.stored_frame()) result.set_frame(*source.stored_frame());
  return result;
}

}  // namespace vola::analysis::detail
