// Network input straight from the VOLA bits: a tree's voxels written into a dense
// float grid (the tensor's memory), optionally turned about the vertical axis, moved
// and scaled (training augmentation; test-time voting turns only).
#pragma once

#include <array>
#include <span>

#include "vola/tree.hpp"

namespace vola::learn {

// Where each voxel goes: turned by `angle_radians` about the z axis through the grid's
// centre, then scaled by `scale` about that centre (x, y and z), then moved by `shift`
// voxels of the tree. Angles that are whole quarter turns (within 1e-9 rad) are done
// with exact integer arithmetic, so that a grid turned by 90 degrees and then by a
// vote's angle lands exactly where the vote 90 degrees further lands.
struct Placement {
  double angle_radians = 0;
  double scale = 1;
  std::array<double, 3> shift{0, 0, 0};
};

// Zeroes `out` (out_side^3 floats, cell (x, y, z) at (x * out_side + y) * out_side + z)
// and sets to 1 every cell a voxel of `tree` falls in: voxel v of a side-N tree falls
// in cell floor(v * out_side / N) (a 64^3 tree into 32^3 is a 2x2x2 "any"). With an
// angle, each voxel centre is first turned by `angle_radians` about the z axis through
// the grid's centre and rounded down to a voxel; voxels turned out of the grid are
// dropped. Visits voxels with Tree::for_each_voxel: work is per voxel, not per cell.
// Throws InvalidArgument when out is not out_side^3 or out_side exceeds the tree side.
void fill_occupancy(const Tree& tree, int out_side, double angle_radians, std::span<float> out);
// The same with a full placement (scale and shift too); voxels placed outside the grid
// are dropped.
void fill_occupancy(const Tree& tree, int out_side, const Placement& placement, std::span<float> out);

// Keeps only the surface of an occupancy grid (side^3 cells, x fastest): a filled cell
// stays when one of its six face neighbours is empty or outside the grid. A solid object
// becomes the one-cell shell a scan or a surface-voxelised mesh gives.
void keep_surface(std::span<float> cells, int side);

// The tree turned by quarter_turns * 90 degrees about z (through the grid's centre):
// voxel (x, y, z) goes to (N-1-y, x, z) for one turn. Exact; for tests and tools.
Tree turn_quarters(const Tree& tree, int quarter_turns);

}  // namespace vola::learn
