// A pinhole camera: one ray per pixel centre, row 0 at the top of the image.
#pragma once

#include <cstdint>
#include <span>

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

// `settings` (up, field of view, image size kept) looking at the centre of the points'
// bounding box from above one of its corners (along -0.55, -0.45, 0.4), as far away as
// every point needs to lie inside the image with a 5% margin: a long strip or a tall
// tower is framed whole, whatever the aspect, and the box's empty corners (a survey
// clipped at an angle) do not push the camera back. `points`: the corners of what must
// be seen (at least one).
PinholeCamera framing(std::span<const Point> points, const PinholeCamera& settings);

// The camera `frames` evenly spaced positions around a vertical (+z) axis through
// look_at, at the eye's distance and height: frame i turned by 360 * i / frames degrees.
PinholeCamera orbit(const PinholeCamera& camera, std::uint32_t frame, std::uint32_t frames);

}  // namespace vola::raycast
