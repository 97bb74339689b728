// Raster tools for the ground filter: a grid of elevations (float cells, NaN = empty),
// morphology with a disk, and filling empty cells. Internal to vola_filters.
#pragma once

#include <cmath>
#include <cstddef>
#include <limits>
#include <vector>

namespace vola::filters::detail {

struct ElevationGrid {
  std::size_t cols = 0, rows = 0;
  double x0 = 0.0, y0 = 0.0;  // corner of cell (0, 0)
  double cell = 1.0;
  std::vector<float> z;       // row-major, NaN where empty

  ElevationGrid() = default;
  ElevationGrid(std::size_t c, std::size_t r, double x, double y, double size)
      : cols(c), rows(r), x0(x), y0(y), cell(size), z(c * r, std::numeric_limits<float>::quiet_NaN()) {}
  std::size_t cells() const noexcept { return z.size(); }
  float& at(std::size_t col, std::size_t row) { return z[row * cols + col]; }
  float at(std::size_t col, std::size_t row) const { return z[row * cols + col]; }
};

// Erosion (minimum) or dilation (maximum) of a grid with no empty cell by the digital
// disk of radius r cells (offsets dx, dy with dx^2 + dy^2 <= r^2); cells beyond the
// edge are left out of the minimum. O(r) per cell.
void erode_disk(const ElevationGrid& in, ElevationGrid& out, int radius);
void dilate_disk(const ElevationGrid& in, ElevationGrid& out, int radius);
// Erosion then dilation: removes what the disk cannot fit under.
void open_disk(const ElevationGrid& in, ElevationGrid& out, int radius);

// Fills every empty cell from the filled ones (a push-pull pyramid of weighted means,
// then Laplace smoothing of the filled-in cells so that they join their neighbours
// without seams); filled cells keep their values. A grid with no value at all is left as is.
void inpaint(ElevationGrid& grid);

// The elevation at (x, y) by bilinear interpolation of the cell centres (clamped at the edges).
double interpolate(const ElevationGrid& grid, double x, double y);

}  // namespace vola::filters::detail
