#include "vola/point_selection.hpp"

namespace vola {
VOLA_INLINE_NAMESPACE_BEGIN

void keep_points(PointCloud& cloud, const std::vector<bool>& keep) {
  std::size_t out = 0;
  const std::size_t n = cloud.size();
  for (std::size_t i = 0; i < n; ++i) {
    if (!keep[i]) continue;
    for (int a = 0; a < 3; ++a) cloud.xyz[3 * out + a] = cloud.xyz[3 * i + a];
    if (!cloud.payload.empty()) cloud.payload[out] = cloud.payload[i];
    for (auto& column : cloud.attributes) column.values[out] = column.values[i];
    ++out;
  }
  cloud.xyz.resize(3 * out);
  if (!cloud.payload.empty()) cloud.payload.resize(out);
  for (auto& column : cloud.attributes) column.values.resize(out);
}

VOLA_INLINE_NAMESPACE_END
}  // namespace vola
