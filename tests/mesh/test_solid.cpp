// Solid fill: the scanline flood fill against a breadth-first search over a dense grid,
// and filled closed meshes against an analytic inside test.
#include <array>
#include <cmath>
#include <queue>
#include <random>

#include <gtest/gtest.h>

#include "mesh_test_support.hpp"
#include "vola/error.hpp"
#include "vola/mesh/voxelize.hpp"

namespace {

using vola::Box;
using vola::Point;
using vola::Quantizer;
using vola::mesh::Triangle;
using vola_test::Xyz;
using vola_mesh_test::XyzSet;

// The obvious way: mark the surface in a dense grid of the padded bounding box, walk
// the outside breadth-first one cell at a time, and list what the walk missed.
XyzSet slow_enclosed(const XyzSet& surface) {
  if (surface.empty()) return {};
  Xyz low = *surface.begin(), high = low;
  for (const Xyz& v : surface)
    for (int a = 0; a < 3; ++a) {
      low[a] = std::min(low[a], v[a]);
      high[a] = std::max(high[a], v[a]);
    }
  const long nx = high[0] - low[0] + 3, ny = high[1] - low[1] + 3, nz = high[2] - low[2] + 3;
  const auto index = [&](long x, long y, long z) { return (z * ny + y) * nx + x; };
  std::vector<char> state(static_cast<std::size_t>(nx * ny * nz), 0);  // 1 surface, 2 outside
  for (const Xyz& v : surface) state[index(v[0] - low[0] + 1, v[1] - low[1] + 1, v[2] - low[2] + 1)] = 1;
  std::queue<std::array<long, 3>> todo;
  todo.push({0, 0, 0});
  state[0] = 2;
  while (!todo.empty()) {
    const auto [x, y, z] = todo.front();
    todo.pop();
    const long steps[6][3] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
    for (const auto& d : steps) {
      const long a = x + d[0], b = y + d[1], c = z + d[2];
      if (a < 0 || b < 0 || c < 0 || a >= nx || b >= ny || c >= nz || state[index(a, b, c)]) continue;
      state[index(a, b, c)] = 2;
      todo.push({a, b, c});
    }
  }
  XyzSet out;
  for (long z = 1; z < nz - 1; ++z)
    for (long y = 1; y < ny - 1; ++y)
      for (long x = 1; x < nx - 1; ++x)
        if (state[index(x, y, z)] == 0)
          out.insert({static_cast<std::uint32_t>(low[0] + x - 1), static_cast<std::uint32_t>(low[1] + y - 1),
                      static_cast<std::uint32_t>(low[2] + z - 1)});
  return out;
}

XyzSet fast_enclosed(const XyzSet& surface) {
  std::vector<vola::Key> keys;
  for (const Xyz& v : surface) keys.push_back(vola::encode(vola_test::to_voxel(v)));
  std::mt19937_64 rng(keys.size());
  std::shuffle(keys.begin(), keys.end(), rng);  // any order will do
  const auto inside = vola::mesh::enclosed_keys(keys);
  const XyzSet out = vola_mesh_test::key_set(inside);
  EXPECT_EQ(out.size(), inside.size()) << "duplicates";
  // The tree built straight from the fill holds the surface and the same inside.
  for (int depth : {4, 5}) {
    XyzSet solid = out;
    solid.insert(surface.begin(), surface.end());
    EXPECT_EQ(vola_test::voxel_set(vola::mesh::solid_tree(keys, depth)), solid) << "depth " << depth;
  }
  return out;
}

void add_shell(XyzSet& s, Xyz low, Xyz high) {
  for (std::uint32_t z = low[2]; z <= high[2]; ++z)
    for (std::uint32_t y = low[1]; y <= high[1]; ++y)
      for (std::uint32_t x = low[0]; x <= high[0]; ++x)
        if (x == low[0] || x == high[0] || y == low[1] || y == high[1] || z == low[2] || z == high[2])
          s.insert({x, y, z});
}

TEST(SolidFill, ShapesMatchTheBreadthFirstSearch) {
  std::vector<std::pair<const char*, XyzSet>> cases;
  XyzSet shell;
  add_shell(shell, {2, 3, 4}, {9, 8, 12});
  cases.emplace_back("hollow box", shell);
  XyzSet leaking = shell;
  leaking.erase({5, 3, 7});  // a hole in one wall
  cases.emplace_back("hollow box with a hole", leaking);
  XyzSet nested = shell;
  add_shell(nested, {4, 5, 6}, {7, 6, 10});
  cases.emplace_back("box in a box", nested);
  XyzSet wide;  // runs longer than a 64-bit word, starting mid-word
  add_shell(wide, {3, 0, 1}, {200, 4, 5});
  add_shell(wide, {70, 1, 2}, {140, 3, 4});
  cases.emplace_back("wide boxes", wide);
  cases.emplace_back("one voxel", XyzSet{{5, 5, 5}});
  XyzSet plane;
  add_shell(plane, {0, 0, 3}, {20, 20, 3});
  cases.emplace_back("a plane", plane);
  std::mt19937_64 rng(21);
  for (double density : {0.2, 0.35, 0.5, 0.65}) {
    for (std::uint32_t width : {12u, 130u}) {
      XyzSet noise;
      std::bernoulli_distribution on(density);
      for (std::uint32_t z = 0; z < 10; ++z)
        for (std::uint32_t y = 0; y < 9; ++y)
          for (std::uint32_t x = 0; x < width; ++x)
            if (on(rng)) noise.insert({x + 7, y, z + 1});
      cases.emplace_back(density < 0.3 ? "sparse noise" : "dense noise", noise);
    }
  }
  for (const auto& [name, surface] : cases) {
    const XyzSet expected = slow_enclosed(surface);
    EXPECT_EQ(fast_enclosed(surface), expected) << name;
  }
  EXPECT_EQ(slow_enclosed(shell).size(), 6u * 4u * 7u);  // the reference itself, once by hand
  EXPECT_TRUE(slow_enclosed(leaking).empty());
}

TEST(SolidFill, RefusesBoxesOverTheLimit) {
  XyzSet shell;
  add_shell(shell, {0, 0, 0}, {9, 9, 9});
  std::vector<vola::Key> keys;
  for (const Xyz& v : shell) keys.push_back(vola::encode(vola_test::to_voxel(v)));
  EXPECT_THROW(vola::mesh::enclosed_keys(keys, 999), vola::InvalidArgument);
  EXPECT_EQ(vola::mesh::enclosed_keys(keys, 1000).size(), 512u);
  EXPECT_THROW(vola::mesh::solid_tree(keys, 2, 999), vola::InvalidArgument);
  EXPECT_EQ(vola::mesh::solid_tree(keys, 2, 1000).voxel_count(), 1000u);
  EXPECT_TRUE(vola::mesh::enclosed_keys({}).empty());
  const vola::Tree empty = vola::mesh::solid_tree({}, 3);
  EXPECT_TRUE(empty.empty());
  EXPECT_EQ(empty.depth(), 3);
}

// Inside a convex polyhedron: on the centre's side of every face plane.
bool inside_convex(const std::vector<Triangle>& mesh, const Point& centre, const Point& p) {
  for (const Triangle& t : mesh) {
    Point e1, e2, n;
    for (int a = 0; a < 3; ++a) {
      e1[a] = t[1][a] - t[0][a];
      e2[a] = t[2][a] - t[0][a];
    }
    n = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
    double side_p = 0, side_c = 0;
    for (int a = 0; a < 3; ++a) {
      side_p += n[a] * (p[a] - t[0][a]);
      side_c += n[a] * (centre[a] - t[0][a]);
    }
    if (side_p * side_c <= 0) return false;
  }
  return true;
}

// For a convex surface every voxel the surface does not touch lies wholly inside or
// wholly outside, and the outside ones reach the border: the solid is the surface plus
// the voxels whose centre is inside.
void expect_convex_solid(const std::vector<Triangle>& mesh, const Point& centre, const Quantizer& q, const char* name) {
  // The surface itself is held to the brute force in test_voxelize.cpp.
  const XyzSet surface = vola_mesh_test::key_set(vola::mesh::surface_keys(mesh, q));
  XyzSet expected = surface;
  const std::uint32_t side = vola::side_of(q.depth());
  for (std::uint32_t z = 0; z < side; ++z)
    for (std::uint32_t y = 0; y < side; ++y)
      for (std::uint32_t x = 0; x < side; ++x)
        if (!surface.count({x, y, z}) && inside_convex(mesh, centre, q.center({x, y, z}))) expected.insert({x, y, z});
  vola::mesh::VoxelizeOptions options;
  options.solid = true;
  vola::mesh::VoxelizeReport report;
  const vola::Tree tree = vola::mesh::voxelize(mesh, q, options, &report);
  EXPECT_EQ(vola_test::voxel_set(tree), expected) << name;
  EXPECT_EQ(report.surface_voxels, surface.size()) << name;
  EXPECT_EQ(report.enclosed_voxels, expected.size() - surface.size()) << name;
  EXPECT_GT(report.enclosed_voxels, 0u) << name;
}

TEST(SolidFill, SphereAndBoxMeshesAgainstTheAnalyticInside) {
  const Point c{0.3, 0.1, -0.2};
  const auto sphere = vola_mesh_test::sphere_mesh(c, 1.0, 2);
  expect_convex_solid(sphere, c, Quantizer::toolkit(vola::mesh::triangle_bounds(sphere), 3), "sphere, toolkit");
  expect_convex_solid(sphere, c, Quantizer::grid({-1.5, -1.5, -1.5}, 0.05, 3), "sphere, grid");
  const Box b{{-0.73, 0.2, 1.1}, {1.9, 2.05, 2.5}};
  const Point bc{(b.min[0] + b.max[0]) / 2, (b.min[1] + b.max[1]) / 2, (b.min[2] + b.max[2]) / 2};
  expect_convex_solid(vola_mesh_test::box_mesh(b), bc, Quantizer::grid({-1, 0, 1}, 0.07, 3), "box, grid");
}

TEST(SolidFill, ToolkitFrameOfABoxFillsTheWholeGrid) {
  const Box b{{1, 2, 3}, {5, 6, 7}};
  vola::mesh::VoxelizeOptions options;
  options.solid = true;
  const vola::Tree tree = vola::mesh::voxelize(vola_mesh_test::box_mesh(b), Quantizer::toolkit(b, 2), options);
  EXPECT_EQ(tree.voxel_count(), 16u * 16u * 16u);
}

TEST(SolidFill, AnOpenBoxEnclosesNothing) {
  auto mesh = vola_mesh_test::box_mesh({{0.1, 0.1, 0.1}, {0.9, 0.9, 0.9}});
  mesh.erase(mesh.begin(), mesh.begin() + 2);  // drop one face
  vola::mesh::VoxelizeOptions options;
  options.solid = true;
  vola::mesh::VoxelizeReport report;
  const vola::Tree tree = vola::mesh::voxelize(mesh, Quantizer::toolkit({{0, 0, 0}, {1, 1, 1}}, 3), options, &report);
  EXPECT_EQ(report.enclosed_voxels, 0u);
  EXPECT_EQ(tree.voxel_count(), report.surface_voxels);
}

}  // namespace
