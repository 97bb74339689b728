// Attribute reductions into a tree whose voxels are already known: points arrive with
// their voxel's rank (Tree::rank, or any rank in key order) and one value per attribute,
// and each voxel's partial is updated in place. Memory follows voxels, not points, and
// nothing is sorted or merged: the second pass of a two-pass conversion (occupancy
// first, then attributes) and the per-tile attribute build of `vola tile` use it.
//
// Points fold in the order they are added, so the values equal vola::build's over the
// same points in the same order, bit for bit (means: the same summation order).
// Reductions and their NaN rules are those of reductions.hpp: mean (NaN, a point without
// a value, skipped; NaN when every value is), max, min (NaN skipped unless every value
// is NaN), last, majority (exact counts; ties to the smallest value; NaN one value after
// every number). A voxel no point reached gets 0.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "vola/attributes.hpp"
#include "vola/stream_builder.hpp"
#include "vola/version.hpp"

namespace vola {
VOLA_INLINE_NAMESPACE_BEGIN

// Where one attribute's value lies in a packed record and how it is decoded: the bytes
// at `offset` as `kind` (little-endian), for the unsigned kinds then (x >> shift) & mask,
// then value * scale + add, in doubles (a LAS field: load, then x * scale + offset), or
// the value as loaded when `scaled` is false (so -0 stays -0). A field of kind u8 or u16
// with scale 1 and add 0 is a whole number in a known range, which the reducer folds as
// an integer.
struct RecordField {
  enum class Kind : std::uint8_t { u8, i8, u16, i16, u32, i32, u64, i64, f32, f64 };
  Kind kind = Kind::f64;
  std::uint32_t offset = 0;
  std::uint8_t shift = 0;
  std::uint64_t mask = ~std::uint64_t{0};
  double scale = 1.0, add = 0.0;
  bool scaled = true;
  bool has_no_data = false;  // the loaded value no_data (before scale and add) gives NaN
  double no_data = 0.0;
};

// A column of values in memory: value i of the attribute is the field at
// data + i * stride (+ field.offset).
struct FieldColumn {
  const std::uint8_t* data = nullptr;
  std::size_t stride = 0;
  RecordField field;
};

class VoxelReducer {
 public:
  VoxelReducer(std::vector<AttributeSpec> specs, std::uint64_t voxels);
  ~VoxelReducer();
  VoxelReducer(VoxelReducer&&) noexcept;
  VoxelReducer& operator=(VoxelReducer&&) noexcept;

  // n points in input order: ranks[i] the voxel of point i (below `voxels`), values[a][i]
  // its value of attribute a. Throws InvalidArgument on a rank out of range or arrays of
  // other lengths.
  void add(std::span<const std::uint64_t> ranks, std::span<const std::span<const double>> values);
  // n points in input order read straight from packed records: point i is the record at
  // records + index[i] * stride (i itself when index is empty), attribute a its field
  // fields[a]. The same partials as add() with the decoded values, without them.
  void add_records(std::span<const std::uint64_t> ranks, const std::uint8_t* records, std::size_t stride,
                   std::span<const std::uint32_t> index, std::span<const RecordField> fields);
  // n points in input order, attribute a's value of point i in columns[a] (say a tree's
  // attribute columns, reduced into a coarser tree's voxels).
  void add_columns(std::span<const std::uint64_t> ranks, std::span<const FieldColumn> columns);
  // One point: values[a] for attribute a (buffered, and reduced in batches, in order).
  void add(std::uint64_t rank, std::span<const double> values);

  // The columns, in the order of the specs; the reducer is empty afterwards.
  std::vector<AttributeColumn> finish();
  // The values of voxels [first, last) only, into out[a] (room for last - first values of
  // attribute a's type, little-endian), and the rows before `last` released: a caller
  // that fills its own columns a range at a time (ranges in increasing order; voxels
  // skipped are not written). No point can be added afterwards; finish() completes the
  // rest. Throws InvalidArgument on a range out of order or out of bounds.
  void finish_range(std::uint64_t first, std::uint64_t last, std::span<std::byte* const> out);
  // Moves the columns into the tree's attributes (the tree has `voxels` voxels).
  void finish_into(Tree& tree);

  std::uint64_t voxels() const noexcept;
  // Bytes held by the partials now.
  std::size_t memory_bytes() const noexcept;

 private:
  void flush_pending();
  void add_now(std::span<const std::uint64_t> ranks, std::span<const std::span<const double>> values);
  void check_ranks(std::span<const std::uint64_t> ranks) const;
  void add_fields(std::span<const std::uint64_t> ranks, std::span<const std::uint32_t> index,
                  std::span<const FieldColumn> columns);
  struct State;
  std::unique_ptr<State> state_;
};

VOLA_INLINE_NAMESPACE_END
}  // namespace vola
