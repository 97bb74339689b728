// Internal: CRC-32C (Castagnoli), the checksum of the .vol extension (docs/FILE_FORMAT.md).
// Written here because the core depends on nothing; SSE4.2's crc32 instruction when the
// build targets it, eight table lookups per word otherwise (same results).
#pragma once

#include <cstdint>
#include <span>

#include "vola/version.hpp"

namespace vola {
VOLA_INLINE_NAMESPACE_BEGIN
namespace detail {

// Continues `crc` (0 to start) over `bytes`: crc32c(a + b) = crc32c(b, crc32c(a)).
std::uint32_t crc32c(std::span<const std::uint8_t> bytes, std::uint32_t crc = 0) noexcept;

}  // namespace detail
VOLA_INLINE_NAMESPACE_END
}  // namespace vola
