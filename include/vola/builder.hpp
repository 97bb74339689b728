// Building trees in bulk: quantize -> keys -> radix sort -> unique -> one pass that
// emits every level's words.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "vola/attributes.hpp"
#include "vola/frame.hpp"
#include "vola/key.hpp"
#include "vola/tree.hpp"
#include "vola/version.hpp"

namespace vola {
VOLA_INLINE_NAMESPACE_BEGIN

// The payload a block gets when a cloud asks for payload words but carries none:
// seven bytes of 0xFF, as the reference writes.
inline constexpr std::uint64_t kDefaultPayload = 0x00FFFFFFFFFFFFFFull;

// One value per point, reduced to one value per voxel.
struct PointAttribute {
  std::string name;
  ValueType type = ValueType::f32;
  Reduction reduction = Reduction::mean;
  std::vector<double> values;  // one per point
};

struct PointCloud {
  std::vector<double> xyz;              // x0 y0 z0 x1 y1 z1 ...
  std::vector<std::uint64_t> payload;   // empty, or one reference payload word per point
  std::vector<PointAttribute> attributes;

  std::size_t size() const noexcept { return xyz.size() / 3; }
  // Per-axis min and max of the finite points (a zero box when there are none).
  Box bounds() const noexcept;
};

struct BuildOptions {
  Quantization quantization = Quantization::toolkit;
  // Toolkit: required. Grid: 0 = the smallest depth that covers the points. A grid the
  // options fix (depth, origin) must hold the bbox (the points' bounds by default), else
  // OptionError: the points outside it would be dropped. A bbox crops.
  int depth = 0;
  // Grid: the voxel edge; 0 = derived from the depth so that the bbox fits.
  double voxel_size = 0.0;
  // Grid: world position of voxel (0,0,0)'s corner; default: the bbox minimum,
  // snapped down to a multiple of the voxel size so that grids of one voxel size
  // line up voxel for voxel.
  std::optional<Point> origin;
  // Default: the points' per-axis bounds (the header records it either way).
  std::optional<Box> bbox;
  // Store one reference payload word per block (header nbits = 1).
  bool payload = false;
  std::uint32_t epsg = 2000;

  // The quantization rules, decided here once for every front end: a depth is 0 or
  // 1..10; toolkit needs a depth and takes no voxel size or origin; grid needs a voxel
  // size or a depth; a voxel size is finite and >= 0; a bbox has min <= max on every
  // axis. Throws OptionError naming the member that is wrong.
  void check() const;
};

struct BuildReport {
  std::uint64_t points_in = 0;
  std::uint64_t points_outside = 0;  // grid mode: outside the grid; any mode: not finite
  std::uint64_t voxels = 0;

  // Fills in the counts of a finished build (null: nothing to report).
  static void of(BuildReport* report, std::uint64_t points_in, std::uint64_t points_outside, const Tree& tree) {
    if (report) *report = BuildReport{points_in, points_outside, tree.voxel_count()};
  }
};

// Points -> tree, with the reference's payload rules and our attribute reductions.
Tree build(const PointCloud& cloud, const BuildOptions& options, BuildReport* report = nullptr);

// Keys in any order, duplicates allowed (the vector is sorted in place).
Tree build_from_keys(std::vector<Key> keys, int depth);
// Keys already sorted and unique (throws InvalidArgument otherwise).
Tree build_from_sorted_keys(std::span<const Key> keys, int depth);
// Integer voxel coordinates, each below 4^depth (throws InvalidArgument otherwise).
Tree build_from_voxels(std::span<const Voxel> voxels, int depth);

// LSD radix sort of keys of `key_bits` significant bits. `index`, if not empty, is
// permuted along (stable: equal keys keep their input order).
void radix_sort(std::vector<Key>& keys, std::vector<std::uint32_t>* index, int key_bits);

// The grid BuildOptions resolve to for a cloud with bounds `bbox` (exposed so that a
// streaming reader can quantize chunk by chunk with the same grid): the depth, origin and
// voxel size the options leave open are derived from the box. Checks the options first.
Quantizer resolve_quantizer(const Box& bbox, const BuildOptions& options);

// Where a build can keep points when the options fix the grid before any point is read
// (grid quantization with a bbox): the grid's cube, a voxel wider on every side for
// rounding at its faces. Readers of spatially indexed files (COPC, EPT) skip the nodes
// that miss it. Nothing when the grid comes from the points, or under toolkit
// quantization, which clamps outside points onto the border voxels.
std::optional<Box> grid_region(const BuildOptions& options);

// The largest anchor + k x step (k whole) at or below `value`: a grid line of a lattice
// through `anchor`. floor(value / step) x step alone can round above the value
// (470692.44 at 0.01), which drops the points at the minimum.
double grid_line_below(double value, double step, double anchor = 0.0);

VOLA_INLINE_NAMESPACE_END
}  // namespace vola
