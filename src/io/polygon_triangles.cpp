#include "polygon_triangles.hpp"

#include <cmath>

namespace vola::io {

namespace {

struct PlanePoint {
  double u, v;
};

double turn_of(const PlanePoint& o, const PlanePoint& a, const PlanePoint& b) noexcept {
  return (a.u - o.u) * (b.v - o.v) - (a.v - o.v) * (b.u - o.u);
}

// Whether p lies inside_triangle or on triangle (a, b, c), counter-clockwise.
bool inside_triangle(const PlanePoint& p, const PlanePoint& a, const PlanePoint& b, const PlanePoint& c) noexcept {
  return turn_of(a, b, p) >= 0.0 && turn_of(b, c, p) >= 0.0 && turn_of(c, a, p) >= 0.0;
}

void fan_of(std::span<const std::uint32_t> left, std::vector<std::array<std::uint32_t, 3>>& out) {
  for (std::size_t k = 1; k + 1 < left.size(); ++k) out.push_back({left[0], left[k], left[k + 1]});
}

}  // namespace

void triangulate_polygon(std::span<const Point> corners, std::vector<std::array<std::uint32_t, 3>>& out) {
  const std::size_t n = corners.size();
  if (n < 3) return;
  std::vector<std::uint32_t> left(n);
  for (std::size_t k = 0; k < n; ++k) left[k] = static_cast<std::uint32_t>(k);
  if (n == 3 || n > kMaxClippedPolygon) return fan_of(left, out);

  // The Newell normal; the polygon is projected along its largest component, and
  // oriented so that the projection turns counter-clockwise.
  double normal[3] = {0.0, 0.0, 0.0};
  for (std::size_t k = 0; k < n; ++k) {
    const Point& a = corners[k];
    const Point& b = corners[(k + 1) % n];
    normal[0] += (a[1] - b[1]) * (a[2] + b[2]);
    normal[1] += (a[2] - b[2]) * (a[0] + b[0]);
    normal[2] += (a[0] - b[0]) * (a[1] + b[1]);
  }
  int drop = 0;
  for (int axis = 1; axis < 3; ++axis)
    if (std::fabs(normal[axis]) > std::fabs(normal[drop])) drop = axis;
  if (!(std::fabs(normal[drop]) > 0.0)) return fan_of(left, out);  // no area (or NaN): nothing to keep inside_triangle
  const int u = (drop + 1) % 3, v = (drop + 2) % 3;                // (u, v, drop) is a right-handed cycle
  const double turn = normal[drop] > 0.0 ? 1.0 : -1.0;
  std::vector<PlanePoint> flat(n);
  for (std::size_t k = 0; k < n; ++k) flat[k] = {corners[k][u], turn * corners[k][v]};

  // Convex (every turn to the left): the fan_of is exact.
  bool convex = true;
  for (std::size_t k = 0; k < n && convex; ++k) convex = turn_of(flat[k], flat[(k + 1) % n], flat[(k + 2) % n]) >= 0.0;
  if (convex) return fan_of(left, out);

  // Ear clipping: a corner whose triangle with its neighbours turns left and holds no
  // other corner is cut off, until a triangle is left.
  std::size_t i = 0, misses = 0;
  while (left.size() > 3) {
    const std::size_t m = left.size();
    i %= m;
    const std::uint32_t a = left[(i + m - 1) % m], b = left[i], c = left[(i + 1) % m];
    bool ear = turn_of(flat[a], flat[b], flat[c]) > 0.0;
    for (std::size_t k = 0; k < m && ear; ++k) {
      const std::uint32_t p = left[k];
      if (p != a && p != b && p != c) ear = !inside_triangle(flat[p], flat[a], flat[b], flat[c]);
    }
    if (ear) {
      out.push_back({a, b, c});
      left.erase(left.begin() + static_cast<std::ptrdiff_t>(i));  // i is c's place now
      misses = 0;
      continue;
    }
    if (++misses > m) return fan_of(left, out);  // no ear: self-intersecting or degenerate
    ++i;
  }
  out.push_back({left[0], left[1], left[2]});
}

}  // namespace vola::io
