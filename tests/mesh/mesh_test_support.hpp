// Helpers of the mesh and terrain tests: the slow references the fast paths are held
// to, and the shared data folder.
#pragma once

#include <cstdint>
#include <random>
#include <set>
#include <span>
#include <vector>

#include "test_support.hpp"
#include "vola/mesh/triangle_box.hpp"

namespace vola_mesh_test {

using vola::mesh::Triangle;
using vola_test::Xyz;
using vola_test::XyzSet;

// $VOLA_SHARED/data.
vola_test::fs::path data_dir();

// Every voxel of the quantizer's grid whose cell box the triangle touches, by testing
// them all (the definition the voxelizer must meet).
XyzSet brute_force_voxels(std::span<const Triangle> triangles, const vola::Quantizer& quantizer);

// An independent overlap test: clip the triangle to the box grown (grow > 0) or shrunk
// (grow < 0) by `grow` on every side, and see whether anything is left.
bool clipped_triangle_meets_box(const Triangle& triangle, const vola::Box& box, double grow);

// Random triangles around `box` of every kind the voxelizer must handle: general,
// slivers, segments, points, tiny, huge, and lying exactly on cell faces of `quantizer`.
std::vector<Triangle> random_triangles(std::mt19937_64& rng, const vola::Box& box, const vola::Quantizer& quantizer,
                                       int count);

// Closed meshes with outward faces: an axis-aligned box and a subdivided icosahedron
// (convex, its vertices on the sphere).
std::vector<Triangle> box_mesh(const vola::Box& box);
std::vector<Triangle> sphere_mesh(const vola::Point& centre, double radius, int subdivisions);

XyzSet key_set(std::span<const vola::Key> keys);

}  // namespace vola_mesh_test

// Skips (or fails with CI set) when the shared data folder is missing.
#define VOLA_REQUIRE_DATA(dir_var)                                                              \
  const ::vola_test::fs::path dir_var = ::vola_mesh_test::data_dir();                           \
  if (!::vola_test::fs::is_directory(dir_var)) {                                                \
    if (std::getenv("CI")) {                                                                    \
      ADD_FAILURE() << "data folder " << dir_var << " is missing (CI is set; set VOLA_SHARED)"; \
      return;                                                                                   \
    }                                                                                           \
    GTEST_SKIP() << "data folder " << dir_var << " is missing; set VOLA_SHARED to run this";     \
  }
