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

// Byte transposition of 64-bit words (all first bytes, then all second bytes, ...):
// occupancy words of one level share their high bytes, which zstd then finds.
std::vector<std::uint8_t> shuffle_words(std::span<const std::uint64_t> words);
std::vector<std::uint64_t> unshuffle_words(std::span<const std::uint8_t> bytes);

}  // namespace detail
VOLA_INLINE_NAMESPACE_END
}  // namespace vola
