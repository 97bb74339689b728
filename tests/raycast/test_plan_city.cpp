// The hierarchical planner on generated cities small enough for the exact search to
// finish: its cost within 1% of the exact optimum, never below it, and every leg of the
// smoothed path clear of the buildings, trees and ground at the radius (issue 22, point 5);
// the same with the space under the sampled ground solid, and then no leg under it.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>

#include "vola/builder.hpp"
#include "vola/raycast/clearance_field.hpp"
#include "vola/raycast/path_planner.hpp"
#include "vola/synth/city.hpp"
#include "plan_checks.hpp"

namespace {

using vola::Point;
using vola::raycast::PlanOptions;
using vola::raycast::plan_path;

// `vola generate city` then `vola convert --voxel-size`: the same points, the same grid.
vola::Tree city(double size, std::uint64_t points, std::uint64_t seed, double voxel_size) {
  vola::synth::CityOptions o;
  o.size = size;
  o.points = points;
  o.seed = seed;
  vola::PointCloud cloud;
  cloud.xyz.reserve(points * 3);
  vola::synth::generate_city(o, [&](const vola::synth::CityPoint& p) { cloud.xyz.insert(cloud.xyz.end(), {p.x, p.y, p.z}); });
  vola::BuildOptions b;
  b.quantization = vola::Quantization::grid;
  b.voxel_size = voxel_size;
  return vola::build(cloud, b);
}

// The lowest free cell centre above the ground of column (x, y): above the highest voxel
// of the 5x5 columns around it (the ground is sampled, not solid), in grid coordinates.
Point above_ground(const vola::Tree& tree, vola::raycast::ClearanceField& field, std::int64_t x, std::int64_t y,
                   std::int64_t ground_below) {
  std::int64_t top = 0;
  for (std::int64_t z = 0; z < ground_below; ++z)
    for (std::int64_t dy = -2; dy <= 2; ++dy)
      for (std::int64_t dx = -2; dx <= 2; ++dx)
        if (tree.contains(vola::Voxel{static_cast<std::uint32_t>(x + dx), static_cast<std::uint32_t>(y + dy),
                                      static_cast<std::uint32_t>(z)}))
          top = z;
  std::int64_t z = top + 1;
  while (!field.free(x, y, z)) ++z;
  return {double(x) + 0.5, double(y) + 0.5, double(z) + 0.5};
}

// Is p under the ground: no voxel at or below it in the 5x5 columns around it, but one
// above (the planner's rule for solid_ground, written the slow way)? Looks 200 cells up.
bool under_ground(const vola::Tree& tree, const Point& p) {
  const auto px = static_cast<std::int64_t>(p[0]), py = static_cast<std::int64_t>(p[1]), pz = static_cast<std::int64_t>(p[2]);
  bool above = false;
  for (std::int64_t y = py - 2; y <= py + 2; ++y)
    for (std::int64_t x = px - 2; x <= px + 2; ++x) {
      if (x < 0 || y < 0 || x >= tree.side() || y >= tree.side()) continue;
      for (std::int64_t z = 0; z < std::min<std::int64_t>(tree.side(), pz + 200); ++z)
        if (tree.contains(static_cast<std::uint32_t>(x), static_cast<std::uint32_t>(y), static_cast<std::uint32_t>(z))) {
          if (z <= pz) return false;
          above = true;
          break;
        }
    }
  return above;
}

// Samples along the legs (a cell apart) that are under the ground.
int legs_under_ground(const vola::Tree& tree, const std::vector<Point>& points) {
  int under = 0;
  for (std::size_t i = 1; i < points.size(); ++i) {
    const Point& a = points[i - 1];
    const Point& b = points[i];
    const double length = std::sqrt((b[0] - a[0]) * (b[0] - a[0]) + (b[1] - a[1]) * (b[1] - a[1]) + (b[2] - a[2]) * (b[2] - a[2]));
    const auto samples = static_cast<int>(std::ceil(length));
    for (int k = 0; k < samples; ++k) {
      const double f = double(k) / samples;
      under += under_ground(tree, {a[0] + f * (b[0] - a[0]), a[1] + f * (b[1] - a[1]), a[2] + f * (b[2] - a[2])});
    }
  }
  return under;
}

struct CityCase {
  double size, voxel_size, radius;  // metres
  std::uint64_t seed;
};

TEST(PlanCity, HierarchicalWithinOnePercentOfExactAndEveryLegClear) {
  // Four million points per 200 m square, as the city: the same point density.
  for (const CityCase c : {CityCase{60, 0.1, 0.3, 1}, CityCase{110, 0.2, 0.4, 2}, CityCase{110, 0.25, 0.5, 3}}) {
    const auto points = static_cast<std::uint64_t>(4e6 * (c.size / 200.0) * (c.size / 200.0));
    const vola::Tree tree = city(c.size, points, c.seed, c.voxel_size);
    const double radius = c.radius / c.voxel_size;
    vola::raycast::ClearanceField field(tree, radius);
    // Ground-level corners, 1 m inside the city's square (the grid's origin is the corner
    // of the points' box, which trees overhanging the square push out).
    const vola::Frame frame = tree.frame();
    const vola::synth::CityOptions defaults;
    const auto cell = [&](double metres, int axis) {
      return static_cast<std::int64_t>(std::floor((defaults.origin[axis] + metres - frame.origin[axis]) / c.voxel_size));
    };
    // The ground rises 0.03 m per metre; roofs start 6 m above it.
    const std::int64_t ground_below = cell(0.03 * c.size + 3.0, 2);
    const Point from = above_ground(tree, field, cell(1.0, 0), cell(1.0, 1), ground_below);
    const Point to = above_ground(tree, field, cell(c.size - 1.0, 0), cell(c.size - 1.0, 1), ground_below);
    PlanOptions exact_options;
    exact_options.radius = radius;
    exact_options.smooth = false;
    auto t0 = std::chrono::steady_clock::now();
    const auto exact = plan_path(tree, from, to, exact_options);
    auto t1 = std::chrono::steady_clock::now();
    PlanOptions options = exact_options;
    options.hierarchical = true;
    const auto coarse_first = plan_path(tree, from, to, options);
    auto t2 = std::chrono::steady_clock::now();
    const std::string name = std::to_string(c.size) + " m city at " + std::to_string(c.voxel_size) + " m";
    EXPECT_GE(coarse_first.cost, exact.cost - 1e-9) << name;
    EXPECT_LE(coarse_first.cost, exact.cost * 1.01) << name;
    // The hierarchical search is the one that scales: it looked at fewer cells.
    EXPECT_LT(coarse_first.expanded, exact.expanded) << name;
    std::printf("%s: exact cost %.6f (%llu expanded, %.2f s), hierarchical %.6f (+%.3f%%, %llu expanded, %.2f s)\n",
                name.c_str(), exact.cost, static_cast<unsigned long long>(exact.expanded),
                std::chrono::duration<double>(t1 - t0).count(), coarse_first.cost,
                100.0 * (coarse_first.cost / exact.cost - 1.0), static_cast<unsigned long long>(coarse_first.expanded),
                std::chrono::duration<double>(t2 - t1).count());
    EXPECT_EQ(vola::test::legs_clear(tree, nullptr, coarse_first.points, radius), "") << name;
    options.smooth = true;
    const auto smooth = plan_path(tree, from, to, options);
    EXPECT_LE(smooth.length, smooth.cost + 1e-9) << name;
    EXPECT_LT(smooth.points.size(), coarse_first.points.size() / 4) << name;
    EXPECT_EQ(vola::test::legs_clear(tree, nullptr, smooth.points, radius), "") << name;
    const int exact_under = legs_under_ground(tree, exact.points);

    // The same with the ground solid: above it all the way, within 1% of that optimum.
    exact_options.solid_ground = options.solid_ground = true;
    options.smooth = false;
    const auto exact_above = plan_path(tree, from, to, exact_options);
    const auto above = plan_path(tree, from, to, options);
    options.smooth = true;
    const auto above_smooth = plan_path(tree, from, to, options);
    EXPECT_GE(exact_above.cost, exact.cost - 1e-9) << name;
    EXPECT_GE(above.cost, exact_above.cost - 1e-9) << name;
    EXPECT_LE(above.cost, exact_above.cost * 1.01) << name;
    std::printf("%s, solid ground: exact cost %.6f (%llu expanded), hierarchical %.6f (+%.3f%%, %llu expanded); "
                "samples under the ground: %d of the exact path without it, %d with it\n",
                name.c_str(), exact_above.cost, static_cast<unsigned long long>(exact_above.expanded), above.cost,
                100.0 * (above.cost / exact_above.cost - 1.0), static_cast<unsigned long long>(above.expanded), exact_under,
                legs_under_ground(tree, exact_above.points));
    EXPECT_EQ(legs_under_ground(tree, above.points), 0) << name;
    EXPECT_EQ(legs_under_ground(tree, above_smooth.points), 0) << name;
    EXPECT_EQ(vola::test::legs_clear(tree, nullptr, above_smooth.points, radius), "") << name;
  }
}

}  // namespace
