// Independent checks of a planned path for the planner's tests: every leg keeps a sphere
// of the radius clear of the obstacles (and, with `known`, of unknown space), by brute
// force over the voxels near points sampled along the leg.
#pragma once

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "vola/frame.hpp"
#include "vola/tree.hpp"

namespace vola::test {

// The smallest squared distance from p to the closed cube of a voxel within reach that
// is occupied (or, with `known`, not known; off the grid counts as unknown).
inline double nearest_obstacle2(const Tree& tree, const Tree* known, const Point& p, double reach) {
  const std::int64_t side = tree.side();
  double best = reach * reach + 1.0;
  const auto lo = [&](int a) { return static_cast<std::int64_t>(std::floor(p[a] - reach)); };
  const auto hi = [&](int a) { return static_cast<std::int64_t>(std::floor(p[a] + reach)); };
  for (std::int64_t z = lo(2); z <= hi(2); ++z)
    for (std::int64_t y = lo(1); y <= hi(1); ++y)
      for (std::int64_t x = lo(0); x <= hi(0); ++x) {
        const bool on_grid = x >= 0 && y >= 0 && z >= 0 && x < side && y < side && z < side;
        const Voxel v{static_cast<std::uint32_t>(x), static_cast<std::uint32_t>(y), static_cast<std::uint32_t>(z)};
        const bool obstacle = on_grid ? tree.contains(v) || (known && !known->contains(v)) : known != nullptr;
        if (!obstacle) continue;
        const double o[3] = {double(x), double(y), double(z)};
        double d2 = 0;
        for (int a = 0; a < 3; ++a) {
          const double n = std::clamp(p[a], o[a], o[a] + 1);
          d2 += (p[a] - n) * (p[a] - n);
        }
        best = std::min(best, d2);
      }
  return best;
}

// Empty when every leg is clear; else what is wrong, for the failure message. Points
// every 1/50 of a cell along each leg; a touch (distance <= radius) is a collision.
inline std::string legs_clear(const Tree& tree, const Tree* known, const std::vector<Point>& points, double radius) {
  for (std::size_t i = 1; i < points.size(); ++i) {
    const Point& a = points[i - 1];
    const Point& b = points[i];
    const double length = std::sqrt((b[0] - a[0]) * (b[0] - a[0]) + (b[1] - a[1]) * (b[1] - a[1]) + (b[2] - a[2]) * (b[2] - a[2]));
    const auto samples = static_cast<int>(std::ceil(length * 50.0));
    for (int k = 0; k <= samples; ++k) {
      const double f = samples ? double(k) / samples : 0.0;
      const Point p{a[0] + f * (b[0] - a[0]), a[1] + f * (b[1] - a[1]), a[2] + f * (b[2] - a[2])};
      const double d2 = nearest_obstacle2(tree, known, p, radius + 1.0);
      if (d2 <= radius * radius + 1e-9)
        return "leg " + std::to_string(i) + " at " + std::to_string(f) + " comes within " + std::to_string(std::sqrt(d2)) +
               " of an obstacle (radius " + std::to_string(radius) + ")";
    }
  }
  return {};
}

}  // namespace vola::test
