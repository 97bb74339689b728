// Internal: the mixed occupancy coder (levels flags 4; docs/FILE_FORMAT.md). The same two
// passes over a level as the context coder of flags 3 (octants of every block, then the
// cells of the set octants), but every bit's probability mixes several context models
// (logistic_mixing.hpp) instead of taking one, and the cells of a block are coded column
// by column (z fastest, then x, then y), so that a cell sees whole columns beside it:
// where the surface is in them. Smaller files (11% on an airborne survey at 1 ft),
// slower to decode.
#pragma once

#include <cstdint>
#include <span>

#include "occupancy_coder.hpp"
#include "range_coder.hpp"
#include "vola/version.hpp"

namespace vola {
VOLA_INLINE_NAMESPACE_BEGIN
namespace detail {

// Codes one level's words (words.size() == near.size(); the decoder's start at 0) given
// each block's neighbours.
void encode_level_mixed(RangeEncoder& coder, std::span<const OccupancyCoder::Neighbours> near,
                        std::span<std::uint64_t> words);
void decode_level_mixed(RangeDecoder& coder, std::span<const OccupancyCoder::Neighbours> near,
                        std::span<std::uint64_t> words);

}  // namespace detail
VOLA_INLINE_NAMESPACE_END
}  // namespace vola
