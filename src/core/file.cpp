#include "vola/file.hpp"

#include <cerrno>
#include <cstdio>
#include <algorithm>
#include <cctype>
#include <cstring>
#include <string_view>

#include "bytes.hpp"
#include "codec.hpp"
#include "dense.hpp"
#include "extension.hpp"
#include "mapped_file.hpp"
#include "vola/error.hpp"
#include "vola/output_file.hpp"

namespace vola {
VOLA_INLINE_NAMESPACE_BEGIN

namespace {

constexpr std::uint8_t kExtensionBit = 0x80;  // in the mode byte: Header::extension

// The pieces of a file, so that write() can stream them without one big copy.
struct Pieces {
  std::uint8_t header[kHeaderSize];
  std::span<const std::uint64_t> body;
  std::vector<std::uint64_t> owned_body;  // dense bodies are made, sparse ones viewed
  detail::ExtensionPieces extension;  // borrows the tree's attribute columns
};

Pieces assemble(const Tree& tree, const WriteOptions& options) {
  Pieces p;
  Header h;
  h.layout = options.layout;
  h.depth = static_cast<std::uint8_t>(tree.depth());
  h.epsg = tree.georef().epsg;
  h.lat = tree.georef().lat;
  h.lon = tree.georef().lon;
  h.bbox = tree.georef().bbox;
  if (options.layout == Layout::dense) {
    // Dense files keep one payload per voxel run, by the reference's rule: state bits
    // would not survive.
    if (tree.payload_meaning() != PayloadMeaning::reference)
      VOLA_THROW(InvalidArgument("an occupancy-state map is written sparse only"));
    if (options.compress) VOLA_THROW(InvalidArgument("compression applies to sparse files only"));
    if (tree.depth() > options.max_dense_depth)
      VOLA_THROW(InvalidArgument("a dense file of depth " + std::to_string(tree.depth()) + " holds " +
                            std::to_string(detail::dense_level_words(tree.depth() - 1)) +
                            " leaf words; write it sparse (dense is allowed up to depth " +
                            std::to_string(options.max_dense_depth) + ")"));
    const bool payload = tree.has_payload() || !tree.voxel_payloads().empty();
    h.nbits = payload ? (tree.nbits() ? tree.nbits() : 1) : 0;
    p.owned_body = detail::encode_dense(tree);
    p.body = p.owned_body;
  } else {
    h.nbits = tree.has_payload() ? tree.nbits() : 0;
    if (options.compress) {
      if (!compression_available()) VOLA_THROW(Error("this vola was built without zstd: cannot compress"));
      h.version = kVersionCompressed;
    } else {
      p.body = tree.words();
    }
  }
  if (options.compress || detail::needs_extension(tree)) {
    detail::append_extension(tree, options.compress, options.compression_level, options.mix_occupancy_models,
                             p.extension);
    h.extension = true;
  }
  encode_header(h, p.header);
  return p;
}

// Sparse levels: N_0 = 1, N_{L+1} = popcount of level L. Returns the number of words
// the levels take, or throws naming the level that runs past the end.
std::uint64_t sparse_extent(std::span<const std::uint8_t> bytes, int depth, bool payload, const std::string& name) {
  const std::uint64_t available = (bytes.size() - kHeaderSize) / 8;
  const std::uint8_t* base = bytes.data() + kHeaderSize;
  std::uint64_t at = 0;
  std::uint64_t blocks = 1;
  for (int level = 0; level < depth; ++level) {
    const std::uint64_t need = blocks * (payload ? 2 : 1);
    if (need > available - at)
      VOLA_THROW(FormatError(name, kHeaderSize + 8 * at,
                        "level " + std::to_string(level) + " needs " + std::to_string(blocks) + " blocks (" +
                            std::to_string(8 * need) + " bytes) but the file ends at byte " +
                            std::to_string(bytes.size()) + " (truncated file" +
                            (payload ? ", or a payload word dropped by the reference writer's zero-payload bug"
                                     : "") +
                            ")"));
    std::uint64_t next = 0;
    for (std::uint64_t i = 0; i < blocks; ++i) {
      std::uint64_t word;
      std::memcpy(&word, base + 8 * (at + i), 8);
      next += static_cast<std::uint64_t>(std::popcount(word));
    }
    at += need;
    blocks = next;
  }
  return at;
}

void apply_extension(Tree& tree, const Header& h, detail::ExtensionContents& ext, const std::string& name,
                     std::uint64_t offset) {
  if (ext.frame) tree.set_frame(*ext.frame);
  if (ext.payload_meaning != PayloadMeaning::reference) {
    if (!tree.has_payload())
      VOLA_THROW(FormatError(name, ext.payload_meaning_offset,
                             "the extension says the payload holds occupancy states, but the header has nbits 0"));
    tree.set_payload_meaning(ext.payload_meaning);
  }
  tree.georef().crs_wkt = std::move(ext.crs_wkt);
  if (!ext.pending.empty()) {
    // Predicted columns need the voxels' places: the frame, or the header's bbox.
    tree.georef().bbox = h.bbox;
    detail::decode_pending_columns(ext, tree, name);
  }
  for (auto& column : ext.attributes) {
    if (column.size() != tree.voxel_count())
      VOLA_THROW(FormatError(name, offset,
                        "attribute '" + column.name() + "' has " + std::to_string(column.size()) +
                            " values for " + std::to_string(tree.voxel_count()) + " voxels"));
    tree.attributes().add(std::move(column));
  }
}

Tree decode(std::span<const std::uint8_t> bytes, const std::string& name, std::shared_ptr<const void> keeper,
            FileLayout* layout, bool in_mapping = false) {
  const Header h = decode_header(bytes, name);
  FileLayout info;
  info.header = h;
  info.file_size = bytes.size();
  const bool payload = h.nbits > 0;
  Tree tree;
  std::uint64_t extension_at = kHeaderSize;
  if (h.version == kVersionCompressed) {
    if (h.layout == Layout::dense)
      VOLA_THROW(FormatError(name, 6, "a compressed (version 2) file must be sparse"));
    auto ext = detail::decode_extension(bytes.subspan(kHeaderSize), name, kHeaderSize, h.depth, payload);
    if (!ext.has_levels)
      VOLA_THROW(FormatError(name, kHeaderSize, "a version-2 file must hold its levels in the extension"));
    tree = Tree::from_levels(h.depth, payload, std::move(ext.levels), name + " (compressed levels)");
    info.compressed_levels = true;
    info.compressed_level_bytes = ext.compressed_level_bytes;
    info.compressed_level_layout = ext.level_layout;
    info.level_bytes = 8 * tree.words().size();
    info.extension_offset = kHeaderSize;
    info.extension_bytes = bytes.size() - kHeaderSize;
    info.extension_version = ext.version;
    apply_extension(tree, h, ext, name, kHeaderSize);
    extension_at = bytes.size();
  } else if (h.layout == Layout::sparse) {
    const std::uint64_t words = sparse_extent(bytes, h.depth, payload, name);
    const std::uint8_t* first = bytes.data() + kHeaderSize;
    if (keeper && reinterpret_cast<std::uintptr_t>(first) % alignof(std::uint64_t) == 0) {
      tree = Tree::view_levels(h.depth, payload, {reinterpret_cast<const std::uint64_t*>(first), words},
                               std::move(keeper), name, kHeaderSize, in_mapping);
    } else {
      std::vector<std::uint64_t> copy(words);
      if (words) std::memcpy(copy.data(), first, 8 * words);
      tree = Tree::from_levels(h.depth, payload, std::move(copy), name, kHeaderSize);
    }
    info.level_bytes = 8 * words;
    extension_at = kHeaderSize + 8 * words;
  } else {
    const std::uint64_t words = detail::dense_body_words(h.depth, payload);
    const std::uint64_t available = (bytes.size() - kHeaderSize) / 8;
    if (words > available)
      VOLA_THROW(FormatError(name, bytes.size(),
                        "a dense file of depth " + std::to_string(h.depth) + (payload ? " with payload" : "") +
                            " needs " + std::to_string(kHeaderSize + 8 * words) + " bytes, the file has " +
                            std::to_string(bytes.size()) + " (truncated file)"));
    std::vector<std::uint64_t> copy(words);
    std::memcpy(copy.data(), bytes.data() + kHeaderSize, 8 * words);
    tree = detail::decode_dense(copy, h.depth, payload, name, kHeaderSize);
    info.level_bytes = 8 * words;
    extension_at = kHeaderSize + 8 * words;
  }
  if (extension_at == bytes.size() && h.extension && h.version != kVersionCompressed)
    VOLA_THROW(FormatError(name, extension_at,
                           "the header says a vola extension (frame, CRS, attributes) follows the levels, but the "
                           "file ends with them: the file is cut"));
  if (extension_at < bytes.size()) {
    const auto rest = bytes.subspan(extension_at);
    if (!detail::starts_extension(rest))
      VOLA_THROW(FormatError(name, extension_at,
                        std::to_string(rest.size()) +
                            " bytes follow the last level and are not a vola extension (trailing garbage)"));
    auto ext = detail::decode_extension(rest, name, extension_at, h.depth);
    if (ext.has_levels)
      VOLA_THROW(FormatError(name, extension_at, "compressed levels in the extension of a version-1 file"));
    apply_extension(tree, h, ext, name, extension_at);
    info.extension_offset = extension_at;
    info.extension_bytes = rest.size();
    info.extension_version = ext.version;
  }
  tree.georef().epsg = h.epsg;
  tree.georef().lat = h.lat;
  tree.georef().lon = h.lon;
  tree.georef().bbox = h.bbox;
  tree.set_nbits(h.nbits);
  if (layout) *layout = info;
  return tree;
}

}  // namespace

bool compression_available() noexcept { return detail::zstd_available(); }

void encode_header(const Header& h, std::uint8_t* out) {
  std::vector<std::uint8_t> bytes;
  detail::ByteWriter w(bytes);
  w.put(h.header_size);
  w.put(h.version);
  w.put(static_cast<std::uint8_t>(static_cast<std::uint8_t>(h.layout) | (h.extension ? kExtensionBit : 0)));
  w.put(h.depth);
  w.put(h.nbits);
  w.put(h.epsg);
  w.put(h.lat);
  w.put(h.lon);
  for (double v : h.bbox.min) w.put(v);
  for (double v : h.bbox.max) w.put(v);
  std::memcpy(out, bytes.data(), kHeaderSize);
}

// What a file that is not a .vol is, from its first bytes, and what to do with it: "a
// LAS file" was reported as "header size 1179861324 is not the 80 this format knows".
const char* other_format(std::span<const std::uint8_t> bytes) {
  struct Signature {
    std::string_view magic;
    const char* what;
  };
  using namespace std::string_view_literals;
  static constexpr Signature kKnown[] = {
      {"LASF"sv, "a LAS/LAZ point file: `vola convert` makes voxels of it, `vola translate` converts its points"},
      {"\x1f\x8b"sv, "gzip-compressed: gunzip it first (gzip -dk FILE)"},
      {"ply"sv, "a PLY file: `vola convert` makes voxels of it, `vola translate` converts its points"},
      {"# .PCD"sv, "a PCD point file: `vola convert` makes voxels of it"},
      {"\x93NUMPY"sv, "a NumPy array: `vola convert` makes voxels of its points"},
      {"PK\x03\x04"sv, "a zip archive (a NumPy .npz? `vola convert` makes voxels of its points)"},
      {"# Octomap"sv, "an OctoMap file: `vola convert` reads it"},
      {"II*\0"sv, "a TIFF (a DEM?): `vola convert` makes voxels of it"},
      {"MM\0*"sv, "a TIFF (a DEM?): `vola convert` makes voxels of it"},
      {"#binvox"sv, "a binvox grid: `vola convert` reads it"},
      {" BDV"sv, "an OpenVDB file: `vola convert` reads it"},
  };
  for (const Signature& s : kKnown)
    if (bytes.size() >= s.magic.size() && std::memcmp(bytes.data(), s.magic.data(), s.magic.size()) == 0) return s.what;
  // A tile index (GeoJSON) given to a command that takes one .vol file.
  std::size_t first = 0;
  while (first < bytes.size() && first < 64 && std::isspace(bytes[first])) ++first;
  if (first < bytes.size() && bytes[first] == '{') {
    const std::string_view head(reinterpret_cast<const char*>(bytes.data()), std::min<std::size_t>(bytes.size(), 4096));
    if (head.find("vola-tile-index") != std::string_view::npos)
      return "a vola tile index: this command takes one .vol file (get, render, plan, view and vola.open_tiles "
             "take tile indexes; or give one of the tiles it names)";
    return "JSON text (a GeoJSON?), not a .vol file";
  }
  // Text (a README, a CSV, an XYZ point file) read as a header said "header size
  // 1870012451 is not the 80 this format knows".
  const std::size_t head = std::min<std::size_t>(bytes.size(), 64);
  if (head >= 8 && std::all_of(bytes.begin(), bytes.begin() + static_cast<std::ptrdiff_t>(head), [](std::uint8_t c) {
        return c == '\n' || c == '\r' || c == '\t' || (c >= 0x20 && c != 0x7f);  // printable ASCII or UTF-8
      }))
    return "text (a point file such as XYZ or CSV? `vola convert` makes voxels of it)";
  return nullptr;
}

Header decode_header(std::span<const std::uint8_t> bytes, const std::string& name) {
  if (const char* what = other_format(bytes)) VOLA_THROW(FormatError(name, 0, std::string("not a .vol file: ") + what));
  if (bytes.size() < kHeaderSize)
    VOLA_THROW(FormatError(name, bytes.size(),
                      "the file is " + std::to_string(bytes.size()) + " bytes, shorter than the 80-byte header"));
  detail::ByteReader r(bytes.first(kHeaderSize), name, 0);
  Header h;
  h.header_size = r.get<std::uint32_t>("header size");
  if (h.header_size != kHeaderSize)
    VOLA_THROW(
        FormatError(name, 0,
                    "header size " + std::to_string(h.header_size) +
                        " is not the 80 this format knows: not a .vol file, or one whose first bytes are damaged"));
  h.version = r.get<std::uint16_t>("version");
  if (h.version != kVersionPlain && h.version != kVersionCompressed)
    VOLA_THROW(FormatError(name, 4, "version " + std::to_string(h.version) + " is not known (1 = reference, 2 = vola compressed)"));
  const auto mode = r.get<std::uint8_t>("mode");
  h.extension = (mode & kExtensionBit) != 0;
  const auto layout = static_cast<std::uint8_t>(mode & 0x7Fu);
  if (layout > 1)
    VOLA_THROW(FormatError(name, 6, "mode " + std::to_string(mode) + " is neither 0 (sparse) nor 1 (dense)"));
  h.layout = static_cast<Layout>(layout);
  h.depth = r.get<std::uint8_t>("depth");
  if (h.depth < kMinDepth || h.depth > kMaxDepth)
    VOLA_THROW(FormatError(name, 7, "depth " + std::to_string(h.depth) + " is outside 1..10"));
  h.nbits = r.get<std::uint32_t>("nbits");
  h.epsg = r.get<std::uint32_t>("crs");
  h.lat = r.get<double>("lat");
  h.lon = r.get<double>("lon");
  for (double& v : h.bbox.min) v = r.get<double>("bbox");
  for (double& v : h.bbox.max) v = r.get<double>("bbox");
  return h;
}

std::vector<std::uint8_t> serialize(const Tree& tree, const WriteOptions& options) {
  const Pieces p = assemble(tree, options);
  std::vector<std::uint8_t> out(kHeaderSize + 8 * p.body.size() + p.extension.size());
  std::memcpy(out.data(), p.header, kHeaderSize);
  if (!p.body.empty()) std::memcpy(out.data() + kHeaderSize, p.body.data(), 8 * p.body.size());
  std::size_t at = kHeaderSize + 8 * p.body.size();
  p.extension.for_each([&](std::span<const std::uint8_t> piece) {
    if (!piece.empty()) std::memcpy(out.data() + at, piece.data(), piece.size());
    at += piece.size();
  });
  return out;
}

void write(const Tree& tree, const std::string& path, const WriteOptions& options) {
  const Pieces p = assemble(tree, options);
  OutputFile out(path);
  out.write(p.header, kHeaderSize);
  out.write(p.body.data(), 8 * p.body.size());
  p.extension.for_each([&](std::span<const std::uint8_t> piece) { out.write(piece.data(), piece.size()); });
  out.commit();
}

Tree parse(std::span<const std::uint8_t> bytes, const std::string& name, FileLayout* layout) {
  return decode(bytes, name, nullptr, layout);
}

Tree read(const std::string& path, FileLayout* layout) {
  const auto file = detail::MappedFile::load(path);
  return decode(file->bytes(), path, nullptr, layout);
}

Tree open_mapped(const std::string& path, FileLayout* layout) {
  const auto file = detail::MappedFile::open(path);
  const auto bytes = file->bytes();
#if defined(__cpp_exceptions) || defined(__EXCEPTIONS)
  // Cut while being checked: the zeros read since make a misleading FormatError; say what happened.
  try {
    Tree tree = decode(bytes, path, file, layout, file->is_mapping());
    check_mapped(tree);
    return tree;
  } catch (const FormatError&) {
    if (detail::MappedFile::lost_at(bytes.data()) == nullptr) throw;
  }
  VOLA_THROW(IoError(path + ": the file was cut (truncated or rewritten in place) while it was being opened"));
#else
  return decode(bytes, path, file, layout, file->is_mapping());
#endif
}

namespace {

void check_mapped(const Tree& tree, bool at_most_every_millisecond) {
  if (!tree.is_mapped()) return;
  const void* words = tree.words().data();
  const detail::MappedFile* lost = detail::MappedFile::lost_at(words);
  if (!lost) lost = detail::MappedFile::rewritten_at(words, at_most_every_millisecond);
  if (lost)
    VOLA_THROW(IoError(lost->path() +
                       ": the file was cut (truncated or rewritten in place) while mapped; what was read from it "
                       "since is void: open it again"));
}

}  // namespace

void check_mapped(const Tree& tree) { check_mapped(tree, false); }
void check_mapped_often(const Tree& tree) { check_mapped(tree, true); }

VOLA_INLINE_NAMESPACE_END
}  // namespace vola
