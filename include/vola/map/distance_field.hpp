// A Euclidean distance field (ESDF, as voxblox and nvblox give planners): for every voxel
// of a box of the tree's grid, the distance from its centre to the centre of the nearest
// occupied voxel, up to a maximum.
//
// Exact, not quasi-Euclidean: the separable squared-distance transform of Felzenszwalb
// and Huttenlocher (2012) along x, then y, then z, over the box grown by the maximum
// distance on every side (so that an obstacle just outside the box counts), in voxel
// units. The only error is the voxelisation itself: distances are between voxel centres
// (a point inside a voxel is up to sqrt(3)/2 voxel from its centre), and values beyond
// `max_distance` read as `max_distance`.
//
// Obstacles are the tree's voxels; a state map's occupied voxels (free and unknown space
// are not obstacles). update() recomputes the part of the box within max_distance of a
// changed region, which equals recomputing the whole (tested against a fresh field).
//
// Costs: O(cells of the grown box) time and 4 bytes per cell of the box (plus a transient
// 4 bytes per cell of the grown box); boxes above kMaxCells cells are refused.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "vola/frame.hpp"
#include "vola/tree.hpp"

namespace vola::map {

struct GridBox {
  std::array<std::int64_t, 3> lo{0, 0, 0};  // first voxel, inclusive (the tree's grid's indices, may be < 0)
  std::array<std::int64_t, 3> hi{0, 0, 0};  // last voxel + 1
};

class DistanceField {
 public:
  static constexpr std::uint64_t kMaxCells = std::uint64_t{1} << 28;

  // The field of `tree`'s obstacles over `box`, distances in world units up to
  // max_distance (> 0). The box may reach past the grid's faces (cells there lie near the
  // obstacles on them); it is clipped max_distance beyond them, where every cell is
  // max_distance. Throws InvalidArgument for an empty box, a non-positive max_distance or
  // a box above kMaxCells cells.
  DistanceField(const Tree& tree, const GridBox& box, double max_distance);
  // The box of the tree's voxels grown by max_distance (past the grid's faces too).
  DistanceField(const Tree& tree, double max_distance);

  // Recomputes the cells within max_distance of `changed` (the tree's grid) from `tree`
  // (the same grid and frame, its voxels changed only inside `changed`).
  void update(const Tree& tree, const GridBox& changed);

  // Distance (world units) at a world point: its voxel's value; max_distance outside the box.
  double distance(const Point& world) const noexcept;
  // The gradient of the distance (world units per world unit; central differences of
  // neighbouring voxels, one-sided at the box's faces): it points away from the nearest
  // obstacle. Zero outside the box.
  Point gradient(const Point& world) const noexcept;
  // The value of voxel v of the tree's grid (inside the box), in voxels.
  float voxels_at(const std::array<std::int64_t, 3>& v) const noexcept;

  const GridBox& box() const noexcept { return box_; }
  double max_distance() const noexcept { return max_distance_; }

 private:
  // Recomputes `region` (inside box_) from the tree's obstacles.
  void compute(const Tree& tree, const GridBox& region);
  bool inside(const std::array<std::int64_t, 3>& v) const noexcept;
  std::size_t index(const std::array<std::int64_t, 3>& v) const noexcept;
  std::array<std::int64_t, 3> voxel_of(const Point& world) const noexcept;

  Frame frame_;
  GridBox box_;
  double max_distance_;       // world units
  double max_voxels_;         // the same in voxels
  std::int64_t margin_;       // voxels: ceil(max_voxels_)
  std::uint32_t side_;        // the tree's grid side
  std::vector<float> values_; // distances in voxels, x fastest, over box_
};

}  // namespace vola::map
