#include "vola/mesh/triangle_box.hpp"

#include <algorithm>
#include <cmath>

namespace vola::mesh {

namespace {

Point minus(const Point& a, const Point& b) noexcept { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }

Point cross(const Point& a, const Point& b) noexcept {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}

double dot(const Point& a, const Point& b) noexcept { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

// Do the projections on `axis` of the triangle (vertices relative to the box's minimum
// corner) and of the box [0, extent] miss each other? A zero axis separates nothing.
bool separated(const Point& axis, const std::array<Point, 3>& rel, const Point& extent) noexcept {
  const double p0 = dot(axis, rel[0]), p1 = dot(axis, rel[1]), p2 = dot(axis, rel[2]);
  double box_low = 0.0, box_high = 0.0;
  for (int a = 0; a < 3; ++a) {
    const double r = axis[a] * extent[a];
    (r < 0.0 ? box_low : box_high) += r;
  }
  return std::min({p0, p1, p2}) > box_high || std::max({p0, p1, p2}) < box_low;
}

}  // namespace

TriangleBoxTest::TriangleBoxTest(const Triangle& triangle) noexcept : vertices_(triangle) {
  for (int a = 0; a < 3; ++a) {
    bounds_.min[a] = std::min({triangle[0][a], triangle[1][a], triangle[2][a]});
    bounds_.max[a] = std::max({triangle[0][a], triangle[1][a], triangle[2][a]});
    for (const Point& v : triangle)
      if (!(std::abs(v[a]) <= kMaxCoordinate)) usable_ = false;  // also NaN
  }
  edges_ = {minus(triangle[1], triangle[0]), minus(triangle[2], triangle[1]), minus(triangle[0], triangle[2])};
  // Scale by a power of two (exact) so that the longest edge component is in [0.5, 1):
  // products of edges and positions then neither underflow for tiny triangles nor
  // overflow for huge ones, and the answer does not change (separation is scale-free).
  // Two factors, as 2^-e alone overflows for subnormal edges.
  double longest = 0.0;
  for (const Point& e : edges_)
    for (double c : e) longest = std::max(longest, std::abs(c));
  if (longest > 0.0 && std::isfinite(longest)) {
    int exponent = 0;
    std::frexp(longest, &exponent);
    scale_[0] = std::ldexp(1.0, -exponent / 2);
    scale_[1] = std::ldexp(1.0, -(exponent - exponent / 2));
  }
  for (Point& e : edges_)
    for (double& c : e) c = c * scale_[0] * scale_[1];
  normal_ = cross(edges_[0], edges_[1]);
}

bool TriangleBoxTest::overlaps(const Box& box) const noexcept {
  if (!usable_) return false;
  // The three box normals: compare bounds. Then shrink the box to the triangle's bounds,
  // which changes no answer (the triangle lies inside them) but makes an infinite box
  // finite and keeps the remaining arithmetic near the triangle.
  Point low, extent;
  for (int a = 0; a < 3; ++a) {
    low[a] = std::max(box.min[a], bounds_.min[a]);
    const double high = std::min(box.max[a], bounds_.max[a]);
    if (!(low[a] <= high)) return false;
    extent[a] = (high - low[a]) * scale_[0] * scale_[1];
  }
  std::array<Point, 3> rel;
  for (int i = 0; i < 3; ++i)
    for (int a = 0; a < 3; ++a) rel[i][a] = (vertices_[i][a] - low[a]) * scale_[0] * scale_[1];
  if (separated(normal_, rel, extent)) return false;
  for (const Point& e : edges_) {
    // e x (1,0,0), e x (0,1,0), e x (0,0,1)
    if (separated({0.0, e[2], -e[1]}, rel, extent)) return false;
    if (separated({-e[2], 0.0, e[0]}, rel, extent)) return false;
    if (separated({e[1], -e[0], 0.0}, rel, extent)) return false;
  }
  return true;
}

bool triangle_box_overlap(const Triangle& triangle, const Box& box) noexcept {
  return TriangleBoxTest(triangle).overlaps(box);
}

}  // namespace vola::mesh
