// The unknown voxels a query reaches (vola/map/unknown_space.hpp).
#include "vola/map/unknown_space.hpp"

#include <algorithm>
#include <array>
#include <cmath>

#include "vola/map/state_map.hpp"

namespace vola::map {

namespace {

bool unknown_at(const Tree& states, double x, double y, double z) {
  const double side = static_cast<double>(states.side());
  const bool inside = x >= 0 && y >= 0 && z >= 0 && x < side && y < side && z < side;
  return !inside ||
         state_at(states, Voxel{std::uint32_t(x), std::uint32_t(y), std::uint32_t(z)}) == VoxelState::unknown;
}

// The unknown cells among [lo, hi) per axis (whole grid indices) that `touches` accepts.
template <class Touches>
std::optional<std::uint64_t> unknown_cells_in(const Tree& states, const std::array<double, 3>& lo,
                                              const std::array<double, 3>& hi, const Touches& touches) {
  double cells = 1;
  for (int i = 0; i < 3; ++i) cells *= std::max(0.0, hi[i] - lo[i]);
  if (!(cells <= static_cast<double>(kMaxUnknownCells))) return std::nullopt;  // NaN too
  std::uint64_t unknown = 0;
  for (double z = lo[2]; z < hi[2]; ++z)
    for (double y = lo[1]; y < hi[1]; ++y)
      for (double x = lo[0]; x < hi[0]; ++x)
        if (touches(x, y, z) && unknown_at(states, x, y, z)) ++unknown;
  return unknown;
}

}  // namespace

std::optional<std::uint64_t> unknown_voxels_on_segment(const Tree& states, const Point& from, const Point& to) {
  if (!is_state_map(states)) return 0;
  double length = 0;
  for (int i = 0; i < 3; ++i) length += (to[i] - from[i]) * (to[i] - from[i]);
  const double samples = std::ceil(std::sqrt(length) * 4) + 1;
  if (!(samples <= static_cast<double>(kMaxUnknownCells))) return std::nullopt;
  const auto steps = static_cast<std::uint64_t>(samples);
  std::uint64_t unknown = 0;
  std::array<double, 3> last{-1, -1, -1};
  bool have_last = false;
  for (std::uint64_t s = 0; s <= steps; ++s) {
    const double t = static_cast<double>(s) / static_cast<double>(steps);
    std::array<double, 3> cell;
    for (int i = 0; i < 3; ++i) cell[i] = std::floor(from[i] + t * (to[i] - from[i]));
    if (have_last && cell == last) continue;  // the same voxel again
    last = cell;
    have_last = true;
    if (unknown_at(states, cell[0], cell[1], cell[2])) ++unknown;
  }
  return unknown;
}

std::optional<std::uint64_t> unknown_voxels_in_sphere(const Tree& states, const Point& centre, double radius) {
  if (!is_state_map(states)) return 0;
  std::array<double, 3> lo{}, hi{};
  for (int i = 0; i < 3; ++i) {
    lo[i] = std::floor(centre[i] - radius);
    hi[i] = std::floor(centre[i] + radius) + 1;
  }
  return unknown_cells_in(states, lo, hi, [&](double x, double y, double z) {
    const double cell[3] = {x, y, z};
    double d2 = 0;  // from the centre to the nearest point of the cell's cube (touching counts)
    for (int i = 0; i < 3; ++i) {
      const double gap = std::max({cell[i] - centre[i], 0.0, centre[i] - (cell[i] + 1)});
      d2 += gap * gap;
    }
    return d2 <= radius * radius;
  });
}

std::optional<std::uint64_t> unknown_voxels_in_box(const Tree& states, const Box& box) {
  if (!is_state_map(states)) return 0;
  std::array<double, 3> lo{}, hi{};
  for (int i = 0; i < 3; ++i) {
    lo[i] = std::floor(box.min[i]);
    hi[i] = std::ceil(box.max[i]);
  }
  return unknown_cells_in(states, lo, hi, [](double, double, double) { return true; });
}

}  // namespace vola::map
