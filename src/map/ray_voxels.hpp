// The voxels a ray passes, in grid units (voxel (i,j,k) = [i,i+1) x [j,j+1) x [k,k+1)):
// Amanatides-Woo over the unbounded integer grid, as OctoMap's computeRayKeys, with the
// crossing times computed from each plane itself (never accumulated), so the only
// rounding is one subtraction and one division per plane, and with every axis that
// crosses at the same time stepping together (a ray through an edge or a corner does not
// pass the voxels it only touches there).
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <limits>

namespace vola::map::detail {

using GridPoint = std::array<double, 3>;
using Cell = std::array<std::int64_t, 3>;

inline Cell cell_of(const GridPoint& p) noexcept {
  return {static_cast<std::int64_t>(std::floor(p[0])), static_cast<std::int64_t>(std::floor(p[1])),
          static_cast<std::int64_t>(std::floor(p[2]))};
}

// Calls visit(cell) for the origin's cell and every cell the segment origin -> end spends
// a positive length in, in order, stopping before the end's cell; nothing when both are
// in one cell. Both points finite.
template <class Visit>
void walk_ray(const GridPoint& origin, const GridPoint& end, Visit&& visit) {
  const Cell first = cell_of(origin), last = cell_of(end);
  if (first == last) return;
  visit(first);
  std::array<double, 3> delta{}, next{}, after{};
  std::array<int, 3> step{};
  Cell cell{};
  // The crossing time of the plane `k` planes ahead of the cell on axis a.
  const auto crossing = [&](int a, std::int64_t k) {
    const double plane = static_cast<double>(step[a] > 0 ? cell[a] + k : cell[a] - k + 1);
    return (plane - origin[a]) / delta[a];
  };
  for (int a = 0; a < 3; ++a) {
    delta[a] = end[a] - origin[a];
    step[a] = delta[a] > 0.0 ? 1 : (delta[a] < 0.0 ? -1 : 0);
    // The cell the segment is in just after t = 0: on a plane moving down, the one below.
    cell[a] = step[a] < 0 ? static_cast<std::int64_t>(std::ceil(origin[a])) - 1 : first[a];
    next[a] = after[a] = std::numeric_limits<double>::infinity();
    if (step[a] != 0) {
      next[a] = crossing(a, 1);
      after[a] = crossing(a, 2);
    }
  }
  // Each step moves an axis towards `last`, so this bounds the walk whatever the
  // rounding (a guard, never reached by a correct walk).
  std::int64_t budget = 4;
  for (int a = 0; a < 3; ++a) budget += std::abs(last[a] - cell[a]) + 1;
  if (cell == last || budget-- <= 0) return;
  if (cell != first) visit(cell);
  for (;;) {
    const double t = std::min(next[0], std::min(next[1], next[2]));
    // The segment ends (t = 1 is the end point) before it leaves this cell.
    if (!(t < 1.0)) return;
    // The next crossing of a stepping axis was computed one step early (`after`), so the
    // division of the one after it is off the loop's critical path; each is still
    // computed from its own plane.
    for (int a = 0; a < 3; ++a) {
      if (next[a] != t) continue;
      cell[a] += step[a];
      next[a] = after[a];
      after[a] = crossing(a, 2);
    }
    // A step moves some axis away from `first` for good, so only the cell before the
    // first step can be `first` again.
    if (cell == last || budget-- <= 0) return;
    visit(cell);
  }
}

}  // namespace vola::map::detail
