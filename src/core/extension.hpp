// Internal: our extension after the levels (docs/FILE_FORMAT.md).
//   "VOLAEXT\0", u32 version, u32 record count, then records:
//   u32 tag, u32 flags, u64 length, `length` bytes, zero padding to 8 bytes.
// Unknown tags are skipped, so later versions can add records.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "vola/attributes.hpp"
#include "vola/frame.hpp"
#include "vola/tree.hpp"

namespace vola {
VOLA_INLINE_NAMESPACE_BEGIN
namespace detail {

inline constexpr std::uint8_t kExtensionMagic[8] = {'V', 'O', 'L', 'A', 'E', 'X', 'T', 0};
inline constexpr std::uint32_t kExtensionVersion = 1;

enum class RecordTag : std::uint32_t { frame = 1, crs_wkt = 2, attribute = 3, levels = 4 };

struct ExtensionContents {
  std::uint32_t version = 0;
  std::optional<Frame> frame;
  std::string crs_wkt;
  std::vector<AttributeColumn> attributes;
  bool has_levels = false;
  std::vector<std::uint64_t> levels;  // decompressed level words (version-2 files)
  std::uint64_t compressed_level_bytes = 0;
};

bool needs_extension(const Tree& tree) noexcept;
bool starts_extension(std::span<const std::uint8_t> bytes) noexcept;
void append_extension(const Tree& tree, bool compress_levels, int level, std::vector<std::uint8_t>& out);
// `base` = file offset of bytes[0]. Checks every length against what is there.
ExtensionContents decode_extension(std::span<const std::uint8_t> bytes, const std::string& name,
                                   std::uint64_t base);

}  // namespace detail
VOLA_INLINE_NAMESPACE_END
}  // namespace vola
