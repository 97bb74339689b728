// NumPy .npy arrays (format versions 1-3): numeric dtypes of either byte order,
// C or Fortran order, and structured (record) dtypes of numeric fields. Used for point
// arrays (N, 3+), record arrays of points and dense occupancy grids (X, Y, Z).
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "vola/builder.hpp"
#include "vola/io/input.hpp"

namespace vola::io {

// One field of a structured (record) dtype, numpy's descr list [('x', '<f8'), ...].
struct NpyField {
  std::string name;
  char kind = 'f';             // 'f' float, 'i' signed, 'u' unsigned, 'b' bool; 'V', 'S', 'U': bytes vola skips
  int item_size = 8;           // bytes of the value
  bool big_endian = false;
  std::uint64_t offset = 0;    // bytes from the start of the record
};

inline constexpr std::uint64_t kNpyValuesAllowance = std::uint64_t{1} << 25;
inline constexpr std::uint64_t kNpyValuesPerStoredByte = 8;

struct NpyArray {
  char kind = 'f';          // 'f' float, 'i' signed, 'u' unsigned, 'b' bool; 'V' records (`fields`)
  int item_size = 8;        // bytes per value (per record for 'V')
  bool big_endian = false;
  bool fortran_order = false;
  std::vector<std::uint64_t> shape;
  // The values as the file lays them out (size() * item_size bytes), viewed in `storage`.
  std::span<const std::uint8_t> data;
  std::shared_ptr<const std::vector<std::uint8_t>> storage;
  // The bytes the array took in its file when they were compressed (an .npz member's
  // deflated size), else 0. Deflate packs a thousand cells of ones in a byte, so the
  // voxels or points read from it are bounded by these bytes (kNpyValuesAllowance +
  // kNpyValuesPerStoredByte per byte, as binvox's runs are), not by the inflated array.
  std::uint64_t compressed_bytes = 0;
  // A structured array's fields (kind 'V'), in record order, padding included.
  std::vector<NpyField> fields;

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

// A structured array (numpy records, as laspy's `points.array` or PDAL's numpy writer
// save them) of any shape as points, one per record: the fields named x, y and z (in
// any case) are the coordinates, every other numeric field an attribute column named
// as text columns are (point_column_name: Intensity -> intensity, ReturnNumber ->
// return_number), array fields one column per element (name_0, name_1, ...); padding,
// byte strings and text are skipped.
PointCloud npy_record_points(const NpyArray& array, const std::string& name);

// A 3-D array as an occupancy grid: cell (i, j, k) is array[i][j][k] (x = first index,
// y = second, z = third), occupied where the value is not zero (NaN is not zero, as in
// numpy.count_nonzero); origin 0, voxel size 1.
VoxelGrid npy_grid(const NpyArray& array, const std::string& name);

// (N, 3+) arrays become points, 3-D arrays grids, structured arrays of any shape points
// (npy_record_points); any other shape gets an error that says which shapes are read (a
// stack of grids: pick one).
Input npy_input(const NpyArray& array, const std::string& name, const InputOptions& options);

}  // namespace vola::io
