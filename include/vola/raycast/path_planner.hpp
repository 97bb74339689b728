// A* over the free voxels of a tree, in voxel-grid coordinates.
//
// The graph: a cell is free when no occupied voxel lies within `radius` of its centre
// (a sphere query; radius 0 = the cell itself is empty); each cell links to its 26
// neighbours at Euclidean cost (1, sqrt 2, sqrt 3), diagonal moves allowed even past
// occupied edge neighbours. The heuristic is the Euclidean distance (consistent), so
// the cost found is optimal. Visited cells live in hash maps: memory follows the search,
// not the volume.
//
// `level` plans on a coarser grid (cells of 4^(depth-1-level) voxels, occupied when any
// voxel inside is); `hierarchical` first plans on a level 2 coarser and then searches
// the fine grid only near that coarse path, falling back to the full search if the
// corridor has no path (its cost is then not guaranteed optimal).
// Smoothing replaces runs of the path by straight segments when a sphere of `radius`
// swept along the segment stays clear (checked conservatively at quarter-cell steps).
// `known` (a state map's tree of known voxels, on the planned tree's grid) makes unknown
// space an obstacle as well: a cell is free only when, besides, every voxel within
// `radius` of its centre (its own voxel at radius 0) is known, and smoothing keeps the
// swept sphere inside known space too. At a coarser level a cell is known when any voxel
// in it is (the fine search, when given, is exact).
#pragma once

#include <cstdint>
#include <vector>

#include "vola/raycast/collision.hpp"

namespace vola::raycast {

struct PlanOptions {
  double radius = 0.0;           // robot radius in voxels
  int level = -1;                // planning level; -1 = the finest (depth - 1)
  bool smooth = true;
  bool hierarchical = false;
  std::uint64_t max_expansions = 20'000'000;  // then the goal counts as unreachable
  const Tree* known = nullptr;   // not owned; null: space outside the tree's voxels is free
};

struct PlannedPath {
  std::vector<Point> points;     // grid coordinates (cell centres, in voxels), start to goal
  double cost = 0.0;             // A* cost in voxels, before smoothing
  double length = 0.0;           // length of `points` in voxels
  std::uint64_t expanded = 0;    // cells taken off the open list
};

// start and goal are points in grid coordinates (voxels). Throws InvalidArgument naming
// the problem: a point outside the volume, inside an obstacle (or closer than the
// radius to one, or to unknown space with `known`), or a goal that cannot be reached.
PlannedPath plan_path(const Tree& tree, const Point& start, const Point& goal, const PlanOptions& options = {});

}  // namespace vola::raycast
