// Internal: the one-pass level emitter shared by the builder, the dense reader and
// the set operations.
#pragma once

#include <cstdint>
#include <span>

#include "vola/tree.hpp"

namespace vola {
VOLA_INLINE_NAMESPACE_BEGIN
namespace detail {

// Sorted unique keys -> tree. With `with_payload`, `voxel_payloads` holds one payload
// per key and each block's payload word follows the reference's rule.
Tree emit_levels(std::span<const Key> keys, int depth, std::span<const std::uint64_t> voxel_payloads,
                 bool with_payload);

// Occupancy only, from the leaf blocks: `blocks` the sorted unique leaf block keys
// (voxel key >> 6) and `bits` their 64 voxel bits each. The same tree as emit_levels
// over the voxel keys, with one step per block instead of one per voxel.
Tree emit_block_levels(std::span<const Key> blocks, std::span<const std::uint64_t> bits, int depth);

}  // namespace detail
VOLA_INLINE_NAMESPACE_END
}  // namespace vola
