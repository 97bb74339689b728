// Where a sphere of a given radius fits: the free cells of a tree's grid for a robot of
// `radius` cells, the planner's clearance test (issue 22, points 4 and 5).
//
// A cell is free when no obstacle voxel's closed cube comes within `radius` of its centre
// (the rule of Collider::sphere: touching counts). For a voxel at integer offset d from
// the cell the squared distance is the sum over the axes of g(d) = (|d| - 1/2)^2 (0 for
// d = 0): a sum of one term per axis, so the blocked cells are the obstacles dilated by
// the fixed set S = {d : g(dx) + g(dy) + g(dz) <= radius^2}, the exact same answer as a
// sphere query per cell, at a few word operations per cell.
//
// The field is computed a brick of 16^3 cells at a time, when first asked for: the
// obstacle words of the brick grown by the reach of S are gathered into rows of bits
// along x, each row dilated along x once per reach, and a brick row is the OR of the
// rows S names. Memory follows what the planner looks at (512 bytes per brick near an
// obstacle, nothing for the empty sky), never the grid's volume. Bricks out of reach
// of every obstacle word are free without a computation.
//
// With `known` (a state map's known voxels on the same grid) unknown space is an obstacle
// too, and so is everything off the grid. Cells off the grid are never free.
//
// With `solid_ground`, the space under the ground is an obstacle too. A map made from
// points has a sampled ground: a sheet with nothing below it, which a planner can pass
// under wherever the sheet ends (a generated city's edge). The ground of column (x, y) is
// taken as its lowest voxel, the smallest within 2 columns on each axis (a sampled ground
// leaves single columns empty; a column under a roof or a crown with no ground point of
// its own gets its neighbours' ground); every cell below it is an obstacle. Columns with
// no voxel within 2 columns have no ground.
//
// Not thread-safe: a query may fill the cache.
#pragma once

#include <array>
#include <bit>
#include <cstdint>
#include <deque>
#include <unordered_map>
#include <vector>

#include "vola/tree.hpp"

namespace vola::raycast {

class ClearanceField {
 public:
  static constexpr int kBrick = 16;  // cells per brick side
  static constexpr int kMaxReach = (64 - kBrick) / 2;  // a gathered row is one 64-bit word

  // `radius` in cells (>= 0, finite); the trees must outlive the field. Throws
  // InvalidArgument when the radius reaches more than kMaxReach cells.
  ClearanceField(const Tree& obstacles, double radius, const Tree* known = nullptr, bool solid_ground = false);

  std::int64_t side() const noexcept { return side_; }
  bool inside(std::int64_t x, std::int64_t y, std::int64_t z) const noexcept {
    return x >= 0 && y >= 0 && z >= 0 && x < side_ && y < side_ && z < side_;
  }
  // Is the cell free? False off the grid.
  bool free(std::int64_t x, std::int64_t y, std::int64_t z);
  // The free cells of brick (bx, by, bz): 256 rows of 16 bits, row y + 16 z, bit x.
  const std::uint16_t* brick(std::int64_t bx, std::int64_t by, std::int64_t bz);
  // Is every cell of the brick free (and on the grid)?
  bool brick_all_free(std::int64_t bx, std::int64_t by, std::int64_t bz);
  std::int64_t bricks_per_side() const noexcept { return (side_ + kBrick - 1) / kBrick; }
  // Bricks whose rows were computed (a measure of the work done).
  std::uint64_t bricks_computed() const noexcept { return computed_; }

 private:
  static std::uint64_t brick_key(std::int64_t bx, std::int64_t by, std::int64_t bz) noexcept {
    return static_cast<std::uint64_t>(bx) | static_cast<std::uint64_t>(by) << 21 | static_cast<std::uint64_t>(bz) << 42;
  }
  // The obstacle word of 4x4x4 block (X, Y, Z) (block coordinates), bit x + 4y + 16z.
  std::uint64_t obstacle_word(std::int64_t X, std::int64_t Y, std::int64_t Z) const noexcept;
  void find_ground(const Tree& obstacles);
  // Could any obstacle be within reach of the brick?
  bool near_obstacle(std::int64_t bx, std::int64_t by, std::int64_t bz) const noexcept;
  // The brick's rows into `out` (256 entries); returns whether every cell is free.
  bool compute(std::int64_t bx, std::int64_t by, std::int64_t bz, std::uint16_t* out);

  std::int64_t side_;
  int reach_;                        // the largest offset in S along one axis
  std::vector<int> reach_x_;         // per (dy, dz) in [-reach, reach]^2: the largest dx in S, -1: none
  bool known_mode_;
  // solid_ground: the ground's height per column over the columns of the voxels' box
  // (grown by 2), INT32_MAX: none; and per brick column, the highest ground within reach.
  std::int64_t ground_x0_ = 0, ground_y0_ = 0, ground_nx_ = 0, ground_ny_ = 0;
  std::vector<std::int32_t> ground_, ground_by_brick_;
  std::int32_t ground_at(std::int64_t x, std::int64_t y) const noexcept;
  // The trees' leaf words by brick, popcount-indexed as VOLA stores a block's children:
  // bit b of `present` says whether the brick's 4x4x4 block b (x + 4y + 16z) has a word,
  // its words in that order from `first`. 8 bytes per leaf word, 40 per brick.
  struct StoredWords {
    std::uint64_t present = 0;
    std::uint64_t first = 0;
  };
  struct StoredBrick {
    StoredWords occupied, known;
  };
  std::uint64_t word_of(const StoredWords& w, int block) const noexcept {
    if (!((w.present >> block) & 1u)) return 0;
    return words_[w.first + static_cast<std::uint64_t>(std::popcount(w.present & ((std::uint64_t{1} << block) - 1)))];
  }
  std::unordered_map<std::uint64_t, StoredBrick> stored_;
  std::vector<std::uint64_t> words_;
  // Computed bricks: slot 0 is the all-free brick, shared. A deque, so that rows handed
  // out stay where they are while later bricks are added.
  std::unordered_map<std::uint64_t, std::uint32_t> rows_of_;
  std::deque<std::array<std::uint16_t, 256>> rows_;
  std::vector<char> slot_all_free_;
  std::uint64_t last_key_ = ~std::uint64_t{0};
  std::uint32_t last_slot_ = 0;
  std::uint64_t computed_ = 0;
  std::vector<std::uint64_t> gathered_, dilated_;  // scratch
};

}  // namespace vola::raycast
