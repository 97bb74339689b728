// Keeping a subset of a point cloud's points, every column along (filters, writers that
// cannot store some points).
#pragma once

#include <vector>

#include "vola/builder.hpp"
#include "vola/version.hpp"

namespace vola {
VOLA_INLINE_NAMESPACE_BEGIN

// Keeps the points whose keep[i] is true, in order, in every column.
void keep_points(PointCloud& cloud, const std::vector<bool>& keep);

VOLA_INLINE_NAMESPACE_END
}  // namespace vola
