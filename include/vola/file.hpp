// .vol files: the reference's 80-byte header and levels (sparse or dense), then, when
// there is something the header cannot say, our extension (docs/FILE_FORMAT.md).
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "vola/frame.hpp"
#include "vola/tree.hpp"
#include "vola/version.hpp"

namespace vola {
VOLA_INLINE_NAMESPACE_BEGIN

inline constexpr std::size_t kHeaderSize = 80;
// Version 1: the reference's layout. Version 2 (ours): the levels are compressed
// inside the extension, so no level words follow the header.
inline constexpr std::uint16_t kVersionPlain = 1;
inline constexpr std::uint16_t kVersionCompressed = 2;

enum class Layout : std::uint8_t { sparse = 0, dense = 1 };

struct Header {
  std::uint32_t header_size = kHeaderSize;
  std::uint16_t version = kVersionPlain;
  Layout layout = Layout::sparse;
  // Bit 7 of the mode byte (vola's; the reference reader ignores the mode byte): our
  // extension follows the levels, so a file that ends with its levels was cut there.
  // Files written before it have the extension without the bit, and still read.
  bool extension = false;
  std::uint8_t depth = 1;
  std::uint32_t nbits = 0;
  std::uint32_t epsg = 2000;
  double lat = 0.0;
  double lon = 0.0;
  Box bbox;
};

// Where things are in a file, for `vola info` and tests.
struct FileLayout {
  Header header;
  std::uint64_t file_size = 0;
  std::uint64_t level_bytes = 0;       // occupancy + payload words as stored
  std::uint64_t extension_offset = 0;  // 0 when there is no extension
  std::uint64_t extension_bytes = 0;
  std::uint32_t extension_version = 0;
  bool compressed_levels = false;
  std::uint64_t compressed_level_bytes = 0;
  // How: 2 zstd of 16-bit lanes, 3 occupancy coded with one context per bit (--compress),
  // 4 with mixed models (--compress-max); docs/FILE_FORMAT.md, levels record.
  std::uint32_t compressed_level_layout = 0;
};

struct WriteOptions {
  Layout layout = Layout::sparse;
  // Compress the levels (context-coded occupancy, zstd payload) and attribute columns
  // (predicted, zstd); sparse only: a version-2 file only vola reads.
  bool compress = false;
  int compression_level = 19;
  // With compress: code the occupancy by mixing several context models per bit (levels
  // flags 4) instead of one: about a tenth smaller on surveys, several times slower to
  // read (docs/FILE_FORMAT.md). Files without it read as before.
  bool mix_occupancy_models = false;
  // Dense files hold 64^(depth-1) leaf words: refuse beyond this depth.
  int max_dense_depth = 5;
};

// Whether this build can write compressed files.
bool compression_available() noexcept;

// The file's bytes. The extension is written only when the tree carries something the
// reference header cannot say (a grid frame, a CRS in WKT, attribute columns, a state
// map's payload meaning) or when compressing, so a toolkit-mode tree serializes exactly
// as the reference writes it.
std::vector<std::uint8_t> serialize(const Tree& tree, const WriteOptions& options = {});
// Writes through a temporary file and a rename: no half-written file on failure.
void write(const Tree& tree, const std::string& path, const WriteOptions& options = {});

// Parses bytes (copied into the tree). `name` labels errors.
Tree parse(std::span<const std::uint8_t> bytes, const std::string& name = {},
           FileLayout* layout = nullptr);
// Reads a file into memory (read(2), no mapping: a file cut meanwhile is a short read).
Tree read(const std::string& path, FileLayout* layout = nullptr);
// Maps a file: a sparse uncompressed file's levels are used in place, never copied.
// Dense and compressed files are decoded into memory.
//
// The tree reads the file's pages as it goes, so it sees the file as it is now: when
// another process cuts the file while it is mapped, the pages past the new end are gone.
// Instead of ending the process with SIGBUS, vola then replaces the whole mapping with
// zero pages (a SIGBUS handler installed by the first open_mapped(), which passes every
// other SIGBUS to the handler that was there before): reads go on, return zeros and
// mean nothing, and check_mapped() says so. A program that installs its own SIGBUS
// handler afterwards replaces this guard. A file rewritten in place to as many bytes or
// more (`cp other.vol mapped.vol`) raises no SIGBUS: check_mapped() finds it by the
// file's size and modification time and treats it as cut.
Tree open_mapped(const std::string& path, FileLayout* layout = nullptr);
// Throws IoError naming the file when `tree` (or a tree sharing its words, e.g. a level
// of detail) maps a file that was cut or rewritten in place since it was opened; does
// nothing otherwise. Call it after reading a mapped tree and before trusting what was read.
// It asks the file system each time (a stat call, about a microsecond).
void check_mapped(const Tree& tree);
// The same for loops that check once per point or ray: a cut is found at once, a rewrite
// in place by a look at the file at most once a millisecond per mapped file.
void check_mapped_often(const Tree& tree);

Header decode_header(std::span<const std::uint8_t> bytes, const std::string& name);
void encode_header(const Header& header, std::uint8_t* out);

VOLA_INLINE_NAMESPACE_END
}  // namespace vola
