// The labelled occupancy-grid sets the classifier is trained on: an .npz archive
// (vola/io/npz.hpp) with an X_<split> array of (N, S, S, S) 0/1 grids beside a
// y_<split> array of N labels.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "vola/io/npz.hpp"

namespace vola::learn {

// N grids of side^3 cells, each 0 or 1, cell (x, y, z) at (x * side + y) * side + z
// (the npy C order of array[n][x][y][z]), with a label 0..9 per grid.
struct LabelledGrids {
  std::string split;  // the <split> of X_<split> / y_<split>
  int side = 32;
  std::vector<std::uint8_t> cells;
  std::vector<int> labels;

  std::size_t size() const noexcept { return labels.size(); }
  std::size_t cells_per_grid() const noexcept { return std::size_t(side) * side * side; }
  std::span<const std::uint8_t> grid(std::size_t i) const noexcept {
    return {cells.data() + i * cells_per_grid(), cells_per_grid()};
  }
};

// Reads X_<split> and y_<split>; an empty `split` picks the archive's only X_* array.
// Checks: X is 4-D (N, S, S, S) with S in 4..256, of an integer, bool or float dtype,
// every value 0 or 1; y is 1-D of N integers in 0..9. Errors name the file, the
// array and what was wrong.
LabelledGrids read_labelled_grids(const std::string& path, const std::string& split = {});

}  // namespace vola::learn
