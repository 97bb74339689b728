// Filters that look at each point's neighbours: height above ground, statistical outlier
// removal, and the two decimations (one point per voxel, Poisson disk).
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "vola/builder.hpp"

namespace vola::filters {

// Height above ground per point: z minus the z of the nearest ground point (class 2)
// in x and y (PDAL's filters.hag_nn with one neighbour); ties go to the point that
// comes first in the file. Throws InvalidArgument when there is no classification column
// or no ground point (run smrf first).
std::vector<double> height_above_ground(const PointCloud& cloud);
// The same as the column "height_above_ground" (f64, mean per voxel), added or replaced.
void add_height_above_ground(PointCloud& cloud);

struct OutlierOptions {
  static constexpr int kMaxNeighbours = 1000;  // time grows with k; beyond, no outlier statistics
  int neighbours = 8;       // k (PDAL's mean_k), 1 .. kMaxNeighbours
  double multiplier = 2.0;  // outliers: mean distance > mean + multiplier x standard deviation
  void check() const;       // throws OptionError
};
// Statistical outliers (PDAL's filters.outlier, method statistical): for each point the
// mean distance (3D) to its k nearest other points; a point is an outlier when that mean
// exceeds the mean over all points by more than multiplier standard deviations (of all
// points' means, population deviation). Returns the outlier flags.
std::vector<bool> statistical_outliers(std::span<const double> xyz, const OutlierOptions& options);

// One point per cube of side `size` (cubes aligned to the points' lowest corner): the one
// nearest the cube's centre, ties to the first in the file. Returns the flags of the
// points kept; they stay in file order.
std::vector<bool> voxel_decimation(std::span<const double> xyz, double size);
// Poisson-disk sampling in file order: a point is kept unless a point kept before it
// lies within `radius` (3D distance < radius). Returns the flags of the points kept.
std::vector<bool> poisson_decimation(std::span<const double> xyz, double radius);

}  // namespace vola::filters
