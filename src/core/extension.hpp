// Internal: our extension after the levels (docs/FILE_FORMAT.md).
//   "VOLAEXT\0", u32 version, u32 record count, then records:
//   u32 tag, u32 flags, u64 length, `length` bytes, zero padding to 8 bytes;
//   from version 2 a trailer: u64 extension length (magic to trailer end), u32 CRC-32C
//   of every extension byte before it, u32 zero.
// Unknown tags are skipped, so later versions can add records. Version-1 extensions
// (no trailer) still read.
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
inline constexpr std::uint32_t kExtensionVersion = 2;
inline constexpr std::uint32_t kFirstVersionWithTrailer = 2;
inline constexpr std::uint64_t kTrailerSize = 16;

enum class RecordTag : std::uint32_t { frame = 1, crs_wkt = 2, attribute = 3, levels = 4, payload_meaning = 5 };

struct ExtensionContents {
  std::uint32_t version = 0;
  std::optional<Frame> frame;
  std::string crs_wkt;
  PayloadMeaning payload_meaning = PayloadMeaning::reference;
  std::uint64_t payload_meaning_offset = 0;  // of its record, for errors
  std::vector<AttributeColumn> attributes;
  // Columns of attribute encodings 2, 3 and 4 (predicted from the voxels or an earlier
  // column), decoded in file order once the tree is known (decode_pending_columns):
  // attributes[index] is named and typed but empty.
  struct PendingColumn {
    std::size_t index;
    std::uint8_t encoding;
    std::uint64_t raw_size;
    std::span<const std::uint8_t> data;  // into the bytes given to decode_extension
    std::uint64_t offset;
  };
  std::vector<PendingColumn> pending;
  bool has_levels = false;
  std::vector<std::uint64_t> levels;  // decompressed level words (version-2 files)
  std::uint64_t compressed_level_bytes = 0;
  std::uint32_t level_layout = 0;  // the levels record's flags: 2, 3 or 4
};

// The extension as the writer emits it: the bytes it builds itself, with the attribute
// columns' raw bytes borrowed from the tree rather than copied (they can be hundreds of
// megabytes; a copy cost a memcpy and as much fresh memory).
struct ExtensionPieces {
  std::vector<std::uint8_t> own;
  // (at, bytes): `bytes` come before own[at]; in increasing `at`
  std::vector<std::pair<std::size_t, std::span<const std::uint8_t>>> borrowed;

  std::uint64_t size() const noexcept;
  bool empty() const noexcept { return size() == 0; }
  // Calls emit(span) for each piece in file order.
  template <class Emit>
  void for_each(Emit&& emit) const {
    std::size_t from = 0;
    for (const auto& [at, bytes] : borrowed) {
      if (at > from) emit(std::span<const std::uint8_t>(own).subspan(from, at - from));
      emit(bytes);
      from = at;
    }
    if (own.size() > from) emit(std::span<const std::uint8_t>(own).subspan(from));
  }
};

bool needs_extension(const Tree& tree) noexcept;
bool starts_extension(std::span<const std::uint8_t> bytes) noexcept;
// The tree's columns must outlive `out` (their bytes are borrowed, not copied).
// `mix_occupancy`: with compress_levels, the mixed occupancy coder (levels flags 4).
void append_extension(const Tree& tree, bool compress_levels, int level, bool mix_occupancy, ExtensionPieces& out);
// `base` = file offset of bytes[0]; `payload` = the header's nbits > 0 (compressed
// levels then hold payload parts); `depth` = the header's, which bounds the level parts
// (one per level, two with payload) before any is decoded. Checks every length against
// what is there.
ExtensionContents decode_extension(std::span<const std::uint8_t> bytes, const std::string& name,
                                   std::uint64_t base, int depth, bool payload = false);
// Decodes the pending columns of `ext` for `tree` (its frame set); a column of another
// length than the tree's voxels is a FormatError.
void decode_pending_columns(ExtensionContents& ext, const Tree& tree, const std::string& name);

}  // namespace detail
VOLA_INLINE_NAMESPACE_END
}  // namespace vola
