// NumPy .npy arrays (format versions 1-3): numeric dtypes of either byte order,
// C or Fortran order. Used for point arrays (N, 3+) and dense occupancy grids (X, Y, Z).
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "vola/builder.hpp"
#include "vola/io/input.hpp"

namespace vola::io {

struct NpyArray {
  char kind = 'f';          // 'f' float, 'i' signed, 'u' unsigned, 'b' bool
  int item_size = 8;        // bytes per value
  bool big_endian = false;
  bool fortran_order = false;
  std::vector<std::uint64_t> shape;
  // The values as the file lays them out (size() * item_size bytes), viewed in `storage`.
  std::span<const std::uint8_t> data;
  std::shared_ptr<const std::vector<std::uint8_t>> storage;

  std::uint64_t size() const noexcept;
  // Value at a C-order multi-index flattened to `index` (Fortran-order files are
  // addressed the same way), converted to double.
  double value(std::uint64_t index) const noexcept;
  std::string dtype() const;
};

// Throws FormatError with the file name and offset on anything malformed; never
// allocates more than the file holds. The first copies the values out of `bytes`; the
// second keeps the buffer and views the values in place.
NpyArray parse_npy(std::span<const std::uint8_t> bytes, const std::string& name);
NpyArray parse_npy(std::vector<std::uint8_t>&& bytes, const std::string& name);
// The file in one read, its values viewed in place.
NpyArray read_npy(const std::string& path);

// An (N, C>=3) array as points: columns 0..2 are x y z, columns 3.. become payload
// bytes (byte k = column 3+k, each 0..255) when `payload_columns` is set.
PointCloud npy_points(const NpyArray& array, const std::string& name, bool payload_columns);

// A 3-D array as an occupancy grid: cell (i, j, k) is array[i][j][k] (x = first index,
// y = second, z = third), occupied where the value is not zero (NaN is not zero, as in
// numpy.count_nonzero); origin 0, voxel size 1.
VoxelGrid npy_grid(const NpyArray& array, const std::string& name);

// (N, 3+) arrays become points, 3-D arrays grids; any other shape gets an error that
// says which shapes are read (a stack of grids: pick one).
Input npy_input(const NpyArray& array, const std::string& name, const InputOptions& options);

}  // namespace vola::io
