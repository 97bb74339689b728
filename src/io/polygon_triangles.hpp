// Polygons of a mesh file (PLY, OFF, ASCII STL) as triangles that stay inside them.
// A fan (0, k, k+1) covers a convex polygon exactly, but a concave one's fan crosses
// the notch and sets voxels the polygon never touches (an L-shaped face's fan covered
// 15 cells of its notch). Concave polygons are cut by ear clipping in the polygon's own
// plane (the Newell normal's dominant axis dropped), as Assimp's triangulation does.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "vola/frame.hpp"

namespace vola::io {

// Corners of a polygon larger than this are cut as a fan: ear clipping costs up to
// n^3 steps, and a file may declare one polygon of millions of corners.
inline constexpr std::size_t kMaxClippedPolygon = 256;

// The triangles (indices into `corners`, in the polygon's winding) covering the polygon
// `corners`, appended to `out`: n - 2 of them for n >= 3 corners, none for fewer. A
// convex polygon gives the fan (0, k, k+1); a concave one its ears; a polygon with no
// ear left (self-intersecting, or degenerate: collinear corners) the fan of what is left.
void triangulate_polygon(std::span<const Point> corners, std::vector<std::array<std::uint32_t, 3>>& out);

}  // namespace vola::io
