// A pinhole camera: one ray per pixel centre, row 0 at the top of the image.
#pragma once

#include <cstdint>

#include "vola/raycast/ray.hpp"

namespace vola::raycast {

struct PinholeCamera {
  Point eye{0, 0, 0};
  Point look_at{0, 1, 0};
  Point up{0, 0, 1};
  double vertical_fov_degrees = 60.0;
  std::uint32_t width = 256;
  std::uint32_t height = 256;

  // Throws InvalidArgument for a zero-sized image, a field of view outside (0, 180),
  // eye == look_at, an up vector parallel to the view, or non-finite values.
  void check() const;
  // The ray through the centre of pixel (column, row): unit direction, no end.
  Ray ray(std::uint32_t column, std::uint32_t row) const noexcept;
};

// The camera `frames` evenly spaced positions around a vertical (+z) axis through
// look_at, at the eye's distance and height: frame i turned by 360 * i / frames degrees.
PinholeCamera orbit(const PinholeCamera& camera, std::uint32_t frame, std::uint32_t frames);

}  // namespace vola::raycast
