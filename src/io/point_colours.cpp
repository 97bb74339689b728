#include "point_colours.hpp"

#include <algorithm>
#include <cmath>

namespace vola::io {

std::optional<ColourScale> colour_scale(char kind, int size) noexcept {
  if ((kind == 'i' || kind == 'u') && size == 1) return ColourScale::bits8;
  if ((kind == 'i' || kind == 'u') && size == 2) return ColourScale::bits16;
  if (kind == 'f' && (size == 4 || size == 8)) return ColourScale::unit;
  return std::nullopt;
}

double colour_attribute(double value, ColourScale scale) noexcept {
  if (scale != ColourScale::unit) return value;
  return std::round(std::clamp(value, 0.0, 1.0) * 255.0);
}

std::uint64_t colour_byte(double value, ColourScale scale) noexcept {
  if (std::isnan(value)) return 0;
  switch (scale) {
    case ColourScale::bits8: return static_cast<std::uint64_t>(std::clamp(value, 0.0, 255.0));
    case ColourScale::bits16: return static_cast<std::uint64_t>(std::clamp(value, 0.0, 65535.0)) >> 8;
    case ColourScale::unit: return static_cast<std::uint64_t>(std::round(std::clamp(value, 0.0, 1.0) * 255.0));
  }
  return 0;
}

ColourColumns::ColourColumns(PointCloud& cloud, ColourScale scale, bool attributes, bool payload)
    : cloud_(cloud), scale_(scale), payload_(payload) {
  if (attributes) {
    first_column_ = cloud.attributes.size();
    for (const char* name : {"red", "green", "blue"})
      cloud.attributes.push_back({name, ValueType::u16, Reduction::mean, {}});
  }
}

void ColourColumns::reserve(std::size_t points) {
  if (first_column_)
    for (std::size_t c = 0; c < 3; ++c) cloud_.attributes[*first_column_ + c].values.reserve(points);
  if (payload_) cloud_.payload.reserve(points);
}

void ColourColumns::add(double red, double green, double blue) {
  if (first_column_) {
    auto* columns = &cloud_.attributes[*first_column_];
    columns[0].values.push_back(colour_attribute(red, scale_));
    columns[1].values.push_back(colour_attribute(green, scale_));
    columns[2].values.push_back(colour_attribute(blue, scale_));
  }
  if (payload_)
    cloud_.payload.push_back(colour_byte(red, scale_) | colour_byte(green, scale_) << 8 |
                             colour_byte(blue, scale_) << 16);
}

}  // namespace vola::io
