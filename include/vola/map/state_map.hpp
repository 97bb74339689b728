// A state map: occupied, free and unknown space in one VOLA tree, the paper's "two bits
// per voxel" (each 64-bit occupancy word mirrored by a 64-bit state word).
//
// The tree holds every KNOWN voxel; its payload word per block (nbits 1) says which of
// them are occupied: at the leaf level bit b is 1 iff voxel b is occupied, 0 iff free; at
// coarser levels bit b is 1 iff cell b holds any occupied voxel, so a walk down the
// payload words answers "any obstacle here?" at every level. Unknown space is outside the
// tree. The tree says it is one with PayloadMeaning::occupancy_state (tree.hpp), stored
// in the file's extension. The attribute column "log_odds" (f32) covers every known voxel.
//
// Costs: state_at is one rank walk (O(depth), no allocation); occupied_tree, free_tree
// and state_counts visit the leaf blocks once.
#pragma once

#include <cmath>
#include <cstdint>
#include <optional>
#include <span>

#include "vola/frame.hpp"
#include "vola/tree.hpp"

namespace vola::map {

class OccupancyMap;

// Values as numpy gets them from the Python module (vola.UNKNOWN, vola.FREE, vola.OCCUPIED).
enum class VoxelState : std::int8_t { unknown = 0, free = 1, occupied = 2 };

const char* name_of(VoxelState state) noexcept;

inline bool is_state_map(const Tree& tree) noexcept {
  return tree.payload_meaning() == PayloadMeaning::occupancy_state;
}

// A voxel's state. A state map: occupied, free, or unknown (not in the tree). Any other
// tree keeps the old meaning: its voxels are occupied and everything else is free.
VoxelState state_at(const Tree& tree, const Voxel& v) noexcept;

// The state of the voxel holding a world point (the tree's frame), with its log-odds
// when the tree has a "log_odds" column and knows the voxel. Outside the grid: unknown
// for a state map, free for any other tree. Made once per tree (the quantizer and the
// column are looked up once), then one rank walk per point; the tree must outlive it.
struct WorldState {
  VoxelState state = VoxelState::unknown;
  std::optional<float> log_odds;
};
class StateLookup {
 public:
  explicit StateLookup(const Tree& tree);
  WorldState at(const Point& p) const noexcept;

 private:
  const Tree& tree_;
  Quantizer quantizer_;
  const AttributeColumn* log_odds_;
};

// OctoMap's probability of a log-odds value: 1 / (1 + exp(-l)).
inline double occupancy_probability(float log_odds) noexcept {
  return 1.0 / (1.0 + std::exp(-static_cast<double>(log_odds)));
}

// The occupied (or free) voxels of a state map as a plain tree: same depth, frame and
// georeferencing, no payload, the attribute columns restricted to those voxels. A tree
// that is not a state map is returned as it is by occupied_tree; free_tree refuses it
// (InvalidArgument: its free space is everything outside it).
Tree occupied_tree(const Tree& state_map);
Tree free_tree(const Tree& state_map);

// A map's free voxels at a coarser `depth`, beside its occupied voxels at that depth: a
// coarse cell holding both is occupied, as OctoMap's inner nodes take their children's
// largest occupancy (exports to .bt/.ot/.vdb/ROS maps need each cell in one state).
// depth 0 or `free`'s own depth: `free` as it is.
Tree free_at_depth(const Tree& free, const Tree& occupied_at_depth, int depth);

struct StateCounts {
  std::uint64_t occupied = 0;
  std::uint64_t free = 0;
  // Cells of the box spanned by the known voxels (grid bounds, inclusive) that are not
  // known; 0 for an empty map.
  std::uint64_t unknown_in_bounds = 0;
  Voxel min{0, 0, 0}, max{0, 0, 0};  // the known voxels' bounds
};
// Counts of a state map (InvalidArgument for another tree).
StateCounts state_counts(const Tree& state_map);

// The map frozen into a state map: grid quantization, voxel size R, origin the map's
// lowest voxel corner (a multiple of R, so tree voxels are map voxels shifted by whole
// cells), the smallest depth that holds every known voxel, "log_odds" for every known
// voxel. Throws InvalidArgument when the known voxels span more than 4^10 per axis.
Tree freeze(const OccupancyMap& map);

// A state map of the known voxels given by state (grid voxels below side_of(depth)), each
// with its log-odds (an empty list: OctoMap's clamping maximum for occupied voxels, its
// minimum for free ones, as a .bt's maximum-likelihood leaves hold), in `frame`. What a
// map file read by another library becomes (vola convert of an OctoMap). Throws
// InvalidArgument for a voxel given twice or outside the grid, a log-odds list of
// another length or a value that is not finite.
Tree state_map_from_voxels(std::span<const Voxel> occupied, std::span<const float> occupied_log_odds,
                           std::span<const Voxel> free, std::span<const float> free_log_odds, int depth,
                           const Frame& frame);

// The map a state map was frozen from (every known voxel with its log-odds), so that more
// scans can be inserted and frozen again: freeze(thaw(freeze(m))) == freeze(m), and
// inserting scans into a thawed map gives the bytes of inserting them all at once.
// Throws InvalidArgument unless `tree` is a state map in grid quantization with a
// "log_odds" column whose origin is a whole number of voxels (what freeze writes).
OccupancyMap thaw(const Tree& state_map);

}  // namespace vola::map
