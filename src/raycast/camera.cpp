#include "vola/raycast/camera.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "vola/error.hpp"

namespace vola::raycast {
namespace {

Point sub(const Point& a, const Point& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
Point cross(const Point& a, const Point& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
double length(const Point& a) { return std::sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]); }
Point normalized(const Point& a) {
  const double n = length(a);
  return {a[0] / n, a[1] / n, a[2] / n};
}

}  // namespace

void PinholeCamera::check() const {
  if (width == 0 || height == 0) throw InvalidArgument("camera: the image needs at least one pixel");
  if (!(vertical_fov_degrees > 0.0 && vertical_fov_degrees < 180.0))
    throw InvalidArgument("camera: the field of view must be between 0 and 180 degrees");
  for (int a = 0; a < 3; ++a)
    if (!std::isfinite(eye[a]) || !std::isfinite(look_at[a]) || !std::isfinite(up[a]))
      throw InvalidArgument("camera: eye, look-at and up must be finite");
  const Point forward = sub(look_at, eye);
  if (length(forward) == 0.0) throw InvalidArgument("camera: the eye and the look-at point are the same");
  if (!(length(cross(forward, up)) > 1e-12 * length(forward) * length(up)))
    throw InvalidArgument("camera: the up vector is parallel to the viewing direction (or zero)");
}

Ray PinholeCamera::ray(std::uint32_t column, std::uint32_t row) const noexcept {
  const Point forward = normalized(sub(look_at, eye));
  const Point right = normalized(cross(forward, up));
  const Point true_up = cross(right, forward);
  const double half = std::tan(vertical_fov_degrees * std::numbers::pi / 360.0);
  const double aspect = static_cast<double>(width) / static_cast<double>(height);
  const double sx = ((column + 0.5) / width * 2.0 - 1.0) * half * aspect;
  const double sy = (1.0 - (row + 0.5) / height * 2.0) * half;
  Point d;
  for (int a = 0; a < 3; ++a) d[a] = forward[a] + sx * right[a] + sy * true_up[a];
  return Ray{eye, normalized(d)};
}

PinholeCamera framing(std::span<const Point> points, const PinholeCamera& settings) {
  if (points.empty()) throw InvalidArgument("framing: nothing to frame");
  Point lo = points.front(), hi = points.front();
  for (const Point& p : points)
    for (int a = 0; a < 3; ++a) lo[a] = std::min(lo[a], p[a]), hi[a] = std::max(hi[a], p[a]);
  PinholeCamera cam = settings;
  for (int a = 0; a < 3; ++a) cam.look_at[a] = 0.5 * (lo[a] + hi[a]);
  const Point from_centre = normalized({-0.55, -0.45, 0.4});
  const Point forward = {-from_centre[0], -from_centre[1], -from_centre[2]};
  const Point side = cross(forward, cam.up);
  const double extent = std::max({hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2], 1e-9});
  double distance = extent;  // an up vector along the view (refused by check()) keeps a plain distance
  if (length(side) > 1e-12 * length(cam.up)) {
    const Point right = normalized(side);
    const Point true_up = cross(right, forward);
    const double aspect = static_cast<double>(std::max(cam.width, 1u)) / static_cast<double>(std::max(cam.height, 1u));
    const double half_v = 0.95 * std::tan(cam.vertical_fov_degrees * std::numbers::pi / 360.0);
    const double half_h = half_v * aspect;
    distance = 0.0;
    for (const Point& p : points) {
      const Point c = sub(p, cam.look_at);
      const double ahead = c[0] * forward[0] + c[1] * forward[1] + c[2] * forward[2];
      const double across = std::abs(c[0] * right[0] + c[1] * right[1] + c[2] * right[2]);
      const double above = std::abs(c[0] * true_up[0] + c[1] * true_up[1] + c[2] * true_up[2]);
      // The corner at depth distance + ahead must show within the half-widths.
      distance = std::max({distance, across / half_h - ahead, above / half_v - ahead});
    }
    distance = std::max(distance, 1e-3 * extent);
  }
  for (int a = 0; a < 3; ++a) cam.eye[a] = cam.look_at[a] + distance * from_centre[a];
  return cam;
}

PinholeCamera orbit(const PinholeCamera& camera, std::uint32_t frame, std::uint32_t frames) {
  PinholeCamera c = camera;
  const double angle = 2.0 * std::numbers::pi * frame / std::max(frames, 1u);
  const double dx = camera.eye[0] - camera.look_at[0], dy = camera.eye[1] - camera.look_at[1];
  c.eye[0] = camera.look_at[0] + dx * std::cos(angle) - dy * std::sin(angle);
  c.eye[1] = camera.look_at[1] + dx * std::sin(angle) + dy * std::cos(angle);
  return c;
}

}  // namespace vola::raycast
