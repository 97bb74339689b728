// Point dimensions by name, as users type them: vola's column names (classification,
// return_number, height_above_ground) and PDAL's (Classification, ReturnNumber,
// HeightAboveGround) name the same column; case and underscores do not matter.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "vola/builder.hpp"

namespace vola::filters {

// The name a column is matched by: lower case, underscores, spaces and bytes outside
// printable ASCII dropped ("ReturnNumber" and "return_number" both give "returnnumber",
// "echo width" and "echo_width" "echowidth").
std::string dimension_key(const std::string& name);

// Where a dimension lives in a cloud: an axis (0 x, 1 y, 2 z) or an attribute column.
struct Dimension {
  int axis = -1;             // 0..2, or -1 for a column
  std::size_t column = 0;    // index into PointCloud::attributes when axis is -1
  int bit = -1;              // >= 0: that bit of the column's values (0 or 1)
};

// The dimension `name` names in `cloud`, or nothing. PDAL's one-bit flags (Synthetic,
// KeyPoint, Withheld, Overlap) are bits 0-3 of classification_flags when the cloud has no
// column of that name.
std::optional<Dimension> find_dimension(const PointCloud& cloud, const std::string& name);
// "x, y, z, intensity, ...": what a cloud offers, for error messages.
std::string dimension_list(const PointCloud& cloud);

// The value of dimension `d` for point i.
inline double value_of(const PointCloud& cloud, const Dimension& d, std::size_t i) {
  if (d.axis >= 0) return cloud.xyz[3 * i + static_cast<std::size_t>(d.axis)];
  const double v = cloud.attributes[d.column].values[i];
  if (d.bit < 0) return v;
  // Flags are a byte; anything else (NaN, negative, a text file's 1e12) holds no flag.
  return v >= 0 && v <= 255 ? static_cast<double>((static_cast<std::uint32_t>(v) >> d.bit) & 1u) : 0.0;
}

// The attribute column named `name` (vola's spelling), added with `type` and `reduction`
// and zero values when the cloud has none; returns its index.
std::size_t ensure_column(PointCloud& cloud, const std::string& name, ValueType type, Reduction reduction);

}  // namespace vola::filters
