// Internal: predictive coding of attribute columns in compressed files (attribute record
// encodings 2 and 3, docs/FILE_FORMAT.md). Lossless for every value type and every bit
// pattern (NaN payloads, infinities, -0.0).
//   2 delta planes: each value minus the one before it in rank order (as a w-byte
//     integer, wrapping; floats by their bit pattern), zig-zag mapped, split into byte
//     planes (all lowest bytes, then all next ones, ...), one zstd frame.
//   3 quantized: floats that are integers times a quantum q (LAS coordinates and their
//     means), coded as those integers minus the integer of the voxel's lower corner along
//     an axis (or minus the previous integer), in byte planes, with the values that are
//     not such an integer stored apart; one zstd frame.
//   4 partner delta planes: each value's step from the previous one minus an earlier
//     column's step at the same rank (green's step predicted by red's), then as 2; the
//     data starts with the partner's index among the attribute records.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "vola/attributes.hpp"
#include "vola/frame.hpp"
#include "vola/tree.hpp"

namespace vola {
VOLA_INLINE_NAMESPACE_BEGIN
namespace detail {

inline constexpr std::uint8_t kEncodingRaw = 0;
inline constexpr std::uint8_t kEncodingZstd = 1;
inline constexpr std::uint8_t kEncodingDeltaPlanes = 2;
inline constexpr std::uint8_t kEncodingQuantized = 3;
inline constexpr std::uint8_t kEncodingPartnerDelta = 4;

// What a column's coding may use besides its values: the voxels' lower corners in world
// coordinates along each axis, in rank order (computed once per tree, on demand).
class VoxelCorners {
 public:
  VoxelCorners(const Tree& tree, const Frame& frame) : tree_(tree), frame_(frame) {}
  // The lower corner of every voxel along `axis` (0 x, 1 y, 2 z), in rank order.
  std::span<const double> along(unsigned axis);

 private:
  const Tree& tree_;
  Frame frame_;
  std::vector<double> corners_[3];
  bool done_[3] = {false, false, false};
};

struct EncodedColumn {
  std::uint8_t encoding = kEncodingRaw;
  std::vector<std::uint8_t> data;
};
// The smallest of zstd, delta planes, (integers) delta planes against the earlier column
// of the same type that predicts best, and (floats) quantized coding of the column.
// `earlier`: the columns written before it, in file order.
EncodedColumn encode_column(const AttributeColumn& column, std::span<const AttributeColumn> earlier,
                            VoxelCorners& corners, int level);
// Decodes `data` (encoding 2, 3 or 4) into `column`, already sized to the tree's voxels;
// `earlier` are the columns before it in the file, decoded. Corrupt data is a FormatError
// naming `name` and `offset`.
void decode_column(std::uint8_t encoding, std::span<const std::uint8_t> data, AttributeColumn& column,
                   std::span<const AttributeColumn> earlier, VoxelCorners& corners, const std::string& name,
                   std::uint64_t offset);

}  // namespace detail
VOLA_INLINE_NAMESPACE_END
}  // namespace vola
