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
    : cloud_(cloud), scale_(scale), payload_(payload), first_payload_(cloud.payload.size()) {
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
  if (scale_ == ColourScale::unit) {  // as read: finish() scales them
    above_one_ = above_one_ || red > 1.0 || green > 1.0 || blue > 1.0;
    if (first_column_) {
      auto* columns = &cloud_.attributes[*first_column_];
      columns[0].values.push_back(red);
      columns[1].values.push_back(green);
      columns[2].values.push_back(blue);
    }
    if (payload_) {
      floats_.insert(floats_.end(), {static_cast<float>(red), static_cast<float>(green), static_cast<float>(blue)});
      cloud_.payload.push_back(0);
    }
    return;
  }
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

void ColourColumns::finish() {
  if (scale_ != ColourScale::unit) return;
  // Floats above 1 anywhere: the channels are 0..255 (as bits8 stores them), else 0..1.
  const ColourScale scale = above_one_ ? ColourScale::bits8 : ColourScale::unit;
  const auto value = [&](double v) {
    return scale == ColourScale::unit ? colour_attribute(v, scale)
           : std::isnan(v)            ? v
                                      : std::round(std::clamp(v, 0.0, 255.0));
  };
  if (first_column_)
    for (std::size_t c = 0; c < 3; ++c)
      for (double& v : cloud_.attributes[*first_column_ + c].values) v = value(v);
  for (std::size_t i = 0; i < floats_.size() / 3; ++i) {
    const float* rgb = &floats_[3 * i];
    cloud_.payload[first_payload_ + i] = colour_byte(scale == ColourScale::unit ? rgb[0] : value(rgb[0]), scale) |
                                         colour_byte(scale == ColourScale::unit ? rgb[1] : value(rgb[1]), scale) << 8 |
                                         colour_byte(scale == ColourScale::unit ? rgb[2] : value(rgb[2]), scale) << 16;
  }
  floats_.clear();
  floats_.shrink_to_fit();
  scale_ = scale;  // a second finish() changes nothing
}

}  // namespace vola::io
