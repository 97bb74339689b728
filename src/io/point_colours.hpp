// Colour channels of point formats (PLY vertex colours, PCD rgb/rgba or red/green/blue
// fields) become the per-voxel attributes red/green/blue (u16, mean) and, when a
// payload is asked for, the reference's payload bytes R, G, B (bytes 0..2, as
// volaviewer draws them).
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

#include "vola/builder.hpp"

namespace vola::io {

// How a channel is stored: 0..255, 0..65535, or a float: 0..1, or 0..255 when any value
// of the file's channels is above 1 (ColourColumns::finish decides).
enum class ColourScale : std::uint8_t { bits8, bits16, unit };

// The scale of a channel stored as `kind` ('i' signed, 'u' unsigned, 'f' float) of
// `size` bytes; nullopt when such a value is not a colour (e.g. 32-bit integers).
std::optional<ColourScale> colour_scale(char kind, int size) noexcept;

// The attribute value kept for a channel value: integers as stored, unit floats as
// 0..255.
double colour_attribute(double value, ColourScale scale) noexcept;
// The payload byte: 8-bit as stored, 16-bit / 256 (as las2vola), unit floats * 255.
std::uint64_t colour_byte(double value, ColourScale scale) noexcept;

// Appends colours point by point to a cloud: adds the red/green/blue columns (when
// `attributes`) and payload words R | G << 8 | B << 16 (when `payload`). Float channels
// are kept as read until finish(), which every reader calls after its last point: many
// tools write float colours as 0..255, which taken as 0..1 all became white.
class ColourColumns {
 public:
  ColourColumns(PointCloud& cloud, ColourScale scale, bool attributes, bool payload);
  void reserve(std::size_t points);
  void add(double red, double green, double blue);
  void finish();

 private:
  PointCloud& cloud_;
  ColourScale scale_;
  std::optional<std::size_t> first_column_;  // index of "red" in cloud.attributes
  bool payload_;
  std::size_t first_payload_ = 0;  // the payload word of the first point added
  std::vector<float> floats_;      // float channels for the payload, until finish()
  bool above_one_ = false;         // a float channel above 1: the file's floats are 0..255
};

}  // namespace vola::io
