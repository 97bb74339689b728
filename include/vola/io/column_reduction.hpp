// How a voxel reduces a point column that nothing else describes, decided by its name as
// every reader decides it (text, PCD, PLY, NumPy, LAS extra bytes) and as Python's
// vola.build does when it is given no reduction.
#pragma once

#include <string_view>

#include "vola/attributes.hpp"

namespace vola::io {

// Classes (classification, class, label), clusters, segments, instances and identifiers
// (id; a name ending in ID/Id after a lower-case letter, a digit or a separator, such as
// treeID and OriginId; or in _id) by majority: the mean of two labels is a third.
// number_of_returns (in any of PDAL's spellings) by maximum; everything else by mean.
Reduction default_reduction(std::string_view name);

}  // namespace vola::io
