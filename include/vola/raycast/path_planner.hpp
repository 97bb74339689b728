// A* over the free cells of a tree's grid, in voxel-grid coordinates.
//
// The graph: a cell is free when no occupied voxel's closed cube lies within `radius` of
// its centre (the rule of Collider::sphere, decided for whole bricks of cells at once by
// ClearanceField, not by a query per cell); each cell links to its 26 neighbours at
// Euclidean cost (1, sqrt 2, sqrt 3). A diagonal move needs every cell of the box it
// spans free (no corner cutting): then the sphere swept along the move stays clear, not
// only at the cells' centres. The heuristic is the 26-neighbour (octile) distance,
// consistent, so the cost found is optimal. The search's state is kept per brick of
// 16^3 cells it reaches: memory follows the search, not the volume.
//
// `level` plans on a coarser grid (cells of 4^(depth-1-level) voxels, occupied when any
// voxel inside is). `hierarchical` first plans over coarse cells of 4^3 cells (a VOLA
// leaf block), passable when at least half their cells are free (the start's and goal's
// always), then runs the fine search only in the coarse cells within one of that route
// (two when that holds no path); then the same along a route through wholly free coarse
// cells; the full search last. Its cost is not guaranteed optimal (within 1% of it on the
// generated cities of tests/raycast/test_plan_city.cpp; docs/BENCHMARKS.md, Planning).
// Smoothing replaces runs of the path by straight segments the sphere can sweep clear,
// decided exactly for the same rule (the segment's walk through the boxes whose corners
// are cell centres, each box needing its corner cells free): every leg of a path, smoothed
// or not, keeps the sphere clear of the obstacles.
// `known` (a state map's tree of known voxels, on the planned tree's grid) makes unknown
// space an obstacle as well: a cell is free only when, besides, every voxel within
// `radius` of its centre (its own voxel at radius 0) is known; cells off the grid are
// unknown. At a coarser level a cell is known when any voxel in it is.
// `solid_ground` makes the space under the ground an obstacle (ClearanceField explains how
// the ground is found): on a map made from points the sampled ground is a sheet, and the
// shortest path between two points on it may pass under it where it ends.
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
  bool solid_ground = false;     // the space under each column's ground is an obstacle (ClearanceField)
  const Frame* world = nullptr;  // not owned; non-null: errors show points and the volume in its world coordinates
};

struct PlannedPath {
  std::vector<Point> points;     // grid coordinates (cell centres, in voxels), start to goal
  double cost = 0.0;             // A* cost in voxels, before smoothing
  double length = 0.0;           // length of `points` in voxels
  std::uint64_t expanded = 0;    // cells taken off the open list
};

// start and goal are points in grid coordinates (voxels). Throws InvalidArgument naming
// the problem: a point outside the volume, inside an obstacle (or closer than the
// radius to one, or to unknown space with `known`), a goal that cannot be reached, or a
// radius of more than ClearanceField::kMaxReach cells (then plan on a coarser level).
PlannedPath plan_path(const Tree& tree, const Point& start, const Point& goal, const PlanOptions& options = {});

}  // namespace vola::raycast
