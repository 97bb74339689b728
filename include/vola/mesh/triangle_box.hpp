// Does a triangle touch a box? The exact separating-axis test of Akenine-Möller
// ("Fast 3D triangle-box overlap testing", 2001): 13 candidate axes, the 3 box normals,
// the triangle's normal and the 9 cross products of a triangle edge with a box axis.
#pragma once

#include <array>

#include "vola/frame.hpp"

namespace vola::mesh {

using Triangle = std::array<Point, 3>;  // the same type as vola::io::Triangle

// Vertices beyond this magnitude are refused: differences of coordinates (edges, a
// vertex minus a box corner) must stay finite.
inline constexpr double kMaxCoordinate = 1e300;

// A triangle prepared for many box tests. Degenerate triangles (segments, points) are
// handled exactly: their zero normal separates nothing and the edge axes still do.
class TriangleBoxTest {
 public:
  explicit TriangleBoxTest(const Triangle& triangle) noexcept;

  // Closed triangle against closed box, in double precision. The box may be infinite
  // on any side (toolkit border voxels). False when the triangle is not usable.
  bool overlaps(const Box& box) const noexcept;
  // The per-axis bounds of the three vertices.
  const Box& bounds() const noexcept { return bounds_; }
  // Every coordinate finite and within +-kMaxCoordinate.
  bool usable() const noexcept { return usable_; }

 private:
  Triangle vertices_;
  std::array<Point, 3> edges_;  // (v1 - v0, v2 - v1, v0 - v2) * scale
  Point normal_;                // edges_[0] x edges_[1]
  std::array<double, 2> scale_{1.0, 1.0};  // powers of two; their product scales lengths
  Box bounds_;
  bool usable_ = true;
};

// TriangleBoxTest(triangle).overlaps(box).
bool triangle_box_overlap(const Triangle& triangle, const Box& box) noexcept;

}  // namespace vola::mesh
