// Internal: optional zstd compression of byte runs. Built without zstd
// (VOLA_WITH_ZSTD=OFF), compressing throws and compressed files cannot be read.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "vola/version.hpp"

namespace vola {
VOLA_INLINE_NAMESPACE_BEGIN
namespace detail {

bool zstd_available() noexcept;
std::vector<std::uint8_t> zstd_compress(std::span<const std::uint8_t> raw, int level);
// Decompresses exactly `raw_size` bytes; throws FormatError (naming `name` and
// `offset`) when the data is corrupt or of another size.
std::vector<std::uint8_t> zstd_decompress(std::span<const std::uint8_t> packed, std::uint64_t raw_size,
                                          const std::string& name, std::uint64_t offset);

// 16-bit lane transposition of 64-bit words: all first 16-bit lanes, then all second
// ones, ... A lane of an occupancy word is one 4x4 z-slice of its brick, and slices of
// neighbouring bricks repeat (a ground plane is the same slice over and over), which
// zstd then finds; measured on the surface benchmark set this beats bytes, 32-bit lanes
// and no transposition.
std::vector<std::uint8_t> lanes16_from_words(std::span<const std::uint64_t> words);
// The inverse; `bytes` holds 8 * words.size() bytes.
void words_from_lanes16(std::span<const std::uint8_t> bytes, std::span<std::uint64_t> words);

}  // namespace detail
VOLA_INLINE_NAMESPACE_END
}  // namespace vola
