// Brick-level morphology shared by dilate and erode.
#pragma once

#include "brick_set.hpp"
#include "vola/analysis/morphology.hpp"

namespace vola::analysis::detail {

// `in` united with its copies shifted by one voxel both ways along `axis`.
BrickSet step_along(const BrickSet& in, int axis);
BrickSet dilate_bricks(const BrickSet& in, int radius, Element element);
// Throws InvalidArgument unless 0 <= radius < the grid side.
void check_radius(const Tree& tree, int radius);

}  // namespace vola::analysis::detail
