// Shared by the export tests: trees built from points the way users build them (grid
// quantization), attribute columns of every kind, and rebuilding a tree from what a
// reader returns on the same grid.
#pragma once

#include <cstdint>
#include <string>

#include "test_support.hpp"
#include "vola/io/input.hpp"

namespace vola_export_test {

using vola_test::fs::path;

struct Grid {
  vola::Point origin{0, 0, 0};
  double voxel_size = 1.0;
  int depth = 1;
  vola::BuildOptions options() const;
};

// A grid for `depth`, with an origin and a voxel size that vary with the seed
// (georeferenced-looking origins, voxel sizes from 5 cm to 2.5 units).
Grid random_grid(std::uint64_t seed, int depth);

// Points 10-90% of the way across each of the voxels (so that they quantize back into
// them), 1-3 per voxel; with `attributes`, per-point values for red/green/blue (u16),
// intensity (u16), classification (u8, majority), number_of_returns (u8, max),
// reflectance (f32), temperature (i16) and pulse (u32).
vola::PointCloud points_in_voxels(const vola_test::XyzSet& voxels, const Grid& grid, std::uint64_t seed,
                                  bool attributes);

// Random voxels of depth `depth` (never empty) as points, built on `grid`.
struct Sample {
  Grid grid;
  vola_test::XyzSet voxels;
  vola::Tree tree;
  std::string describe;
};
Sample random_sample(std::uint64_t seed, int depth, bool attributes);

// vola::build on `grid`; fails the test if a point falls outside it.
vola::Tree build_on(const vola::PointCloud& cloud, const Grid& grid);

// A reader's points built on `grid` (the input must hold points).
vola::Tree rebuild(const vola::io::Input& input, const Grid& grid);

// $VOLA_SHARED/data (the golden folder's sibling).
path data_dir();

}  // namespace vola_export_test

// Skips the test when a shared data file is missing, or fails it when CI is set.
#define VOLA_REQUIRE_DATA_FILE(file)                                                     \
  if (!::vola_test::fs::exists(file)) {                                                  \
    if (std::getenv("CI")) {                                                             \
      ADD_FAILURE() << (file) << " is missing (CI is set; set VOLA_SHARED)";             \
      return;                                                                            \
    }                                                                                    \
    GTEST_SKIP() << (file) << " is missing; set VOLA_SHARED to run this";                \
  }
