// Where the voxel grid sits in the world, and how points become voxels.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "vola/key.hpp"
#include "vola/version.hpp"

namespace vola {
VOLA_INLINE_NAMESPACE_BEGIN

using Point = std::array<double, 3>;

struct Box {
  Point min{0, 0, 0};
  Point max{0, 0, 0};
  friend bool operator==(const Box&, const Box&) = default;
};

// toolkit: the reference implementation's rounding against the longest bbox side
//          (FORMAT.md section 6); the grid is fixed by the header bbox and the depth.
// grid:    floor((p - origin) / voxel_size), the GIS convention; origin and voxel
//          size are recorded in the file's extension.
enum class Quantization : std::uint8_t { toolkit = 0, grid = 1 };

// A voxel grid in world coordinates: voxel (i, j, k) covers
// [origin + i*voxel_size, origin + (i+1)*voxel_size) on each axis.
struct Frame {
  Quantization quantization = Quantization::toolkit;
  Point origin{0, 0, 0};
  double voxel_size = 1.0;
  friend bool operator==(const Frame&, const Frame&) = default;
};

// The georeferencing the reference header carries, plus the CRS as WKT when known.
struct Georef {
  std::uint32_t epsg = 2000;  // the reference's default code
  double lat = 0.0;           // WGS84 latitude of the bbox centre
  double lon = 0.0;           // WGS84 longitude of the bbox centre
  Box bbox;                   // raw bbox of the input points (not a cube)
  std::string crs_wkt;        // empty when unknown
  friend bool operator==(const Georef&, const Georef&) = default;
};

// Maps points to voxels for one depth, in either quantization mode.
class Quantizer {
 public:
  // The reference's rule: n = clip((p - min) / ((min + Lmax) - min), 0, 1),
  // v = round_half_even((S - 1) * n). A zero-extent bbox puts every point in voxel 0
  // (the reference computes 0/0 there).
  static Quantizer toolkit(const Box& bbox, int depth);
  // floor((p - origin) / voxel_size); points outside 0..S-1 are rejected.
  static Quantizer grid(const Point& origin, double voxel_size, int depth);

  // False when the point falls outside the grid (grid mode only; toolkit clamps)
  // or is not finite.
  bool to_voxel(const Point& p, Voxel& out) const noexcept;
  // The keys of the points xyz (x y z per point) that to_voxel places, appended to `keys`
  // in input order; `kept`, when not null, gets each placed point's index. The same
  // arithmetic as to_voxel with the mode's branches out of the loop. Returns how many
  // points were dropped.
  std::uint64_t to_keys(std::span<const double> xyz, std::vector<Key>& keys, std::vector<std::uint32_t>* kept) const;
  // Centre of a voxel in world coordinates.
  Point center(const Voxel& v) const noexcept;
  // The grid as origin + voxel size (toolkit: origin = min - step/2, step = Lmax/(S-1)).
  Frame frame() const noexcept;
  // The closed box of the world points to_voxel maps to `v` (up to rounding in the last
  // bit); neighbouring voxels share their faces bit for bit. Toolkit mode clamps, so its
  // border voxels reach to infinity outward, and a zero-extent toolkit bbox gives voxel
  // 0 all of space and every other voxel an empty box (min > max). (An axis whose
  // (min + Lmax) - min rounds to 0 collapses the voxels between its border ones onto
  // the plane at min.)
  Box cell_box(const Voxel& v) const noexcept;
  // The voxels [first, last] (per axis) whose cell boxes may touch `box`: every voxel
  // whose cell_box intersects it, plus at most the neighbour on each side that rounding
  // could put there (the whole axis where the arithmetic overflows). False when no
  // voxel can (box empty or NaN, or outside a grid-mode grid).
  bool voxel_range(const Box& box, Voxel& first, Voxel& last) const noexcept;
  int depth() const noexcept { return depth_; }

 private:
  Quantization mode_ = Quantization::toolkit;
  int depth_ = 1;
  Point origin_{};     // toolkit: bbox min; grid: origin
  Point scale_{};      // toolkit: (min + Lmax) - min per axis; grid: voxel size
  bool degenerate_ = false;  // toolkit with a zero-extent bbox
};

// The smallest depth whose grid of `voxel_size` voxels covers `extent` on every axis.
int depth_for_extent(double extent, double voxel_size);

VOLA_INLINE_NAMESPACE_END
}  // namespace vola
