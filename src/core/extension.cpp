#include "extension.hpp"

#include <algorithm>

#include <cmath>
#include <cstring>
#include <string>
#include <unordered_set>

#include "bytes.hpp"
#include "codec.hpp"
#include "column_codec.hpp"
#include "occupancy_coder.hpp"
#include "crc32c.hpp"

namespace vola {
VOLA_INLINE_NAMESPACE_BEGIN
namespace detail {

namespace {

// A compressed record may claim at most this many raw bytes per stored byte (plus a
// little), so a lying length cannot make us allocate far beyond the file's size.
constexpr std::uint64_t kMaxRatio = 8192;
constexpr std::uint64_t kRatioSlack = 1 << 20;
// Levels record flags: the layout of the parts (each level's occupancy words, then its
// payload words). 2: one zstd frame per part, in 16-bit lanes. 3: occupancy parts coded
// by the context-modelled arithmetic coder (occupancy_coder.hpp), payload parts as in 2.
// 4: as 3 with the models mixed (occupancy_mixed.hpp).
constexpr std::uint32_t kLanes16PerPart = 2;
constexpr std::uint32_t kCodedOccupancy = 3;
constexpr std::uint32_t kMixedOccupancy = 4;

void begin_record(ByteWriter& w, RecordTag tag, std::uint32_t flags, std::uint64_t length) {
  w.put(static_cast<std::uint32_t>(tag));
  w.put(flags);
  w.put(length);
}

std::string hex32(std::uint32_t v) {
  char s[11] = "0x";
  for (int i = 0; i < 8; ++i) s[2 + i] = "0123456789abcdef"[(v >> (28 - 4 * i)) & 15u];
  return s;
}

std::span<const std::uint8_t> as_bytes(const std::string& s) {
  return {reinterpret_cast<const std::uint8_t*>(s.data()), s.size()};
}

void check_ratio(ByteReader& r, std::uint64_t raw, std::uint64_t packed) {
  if (raw > packed * kMaxRatio + kRatioSlack)
    r.fail("record claims " + std::to_string(raw) + " bytes from " + std::to_string(packed) +
           " compressed bytes, more than any real data compresses");
}

// The length and the checksum cover the whole extension (the length field included), so
// a cut or a flipped bit anywhere in it, attribute values too, is an error rather than
// lost or wrong metadata.
void append_trailer(ExtensionPieces& out) {
  ByteWriter w(out.own);
  w.put(static_cast<std::uint64_t>(out.size() + kTrailerSize));
  std::uint32_t crc = 0;
  out.for_each([&](std::span<const std::uint8_t> piece) { crc = crc32c(piece, crc); });
  w.put(crc);
  w.put(std::uint32_t{0});
}

// Checks the trailer that ends a version-2 extension; `r` is just past the last record.
void check_trailer(ByteReader& r, std::span<const std::uint8_t> bytes, std::uint64_t base) {
  const std::uint64_t at = r.offset();
  if (r.remaining() < kTrailerSize)
    r.fail("the extension ends " + std::to_string(r.remaining()) +
           " bytes after its last record, before its length and checksum: the file is cut");
  const auto length = r.get<std::uint64_t>("extension length");
  const std::uint32_t actual = crc32c(bytes.first(static_cast<std::size_t>(at - base + 8)));
  const auto stored = r.get<std::uint32_t>("extension checksum");
  if (r.get<std::uint32_t>("reserved") != 0) r.fail_at(at + 12, "the extension trailer's reserved word is not 0");
  if (length != at - base + kTrailerSize)
    r.fail_at(at, "the extension says it is " + std::to_string(length) + " bytes long, it is " +
                      std::to_string(at - base + kTrailerSize));
  if (stored != actual)
    r.fail_at(at + 8, "extension checksum " + hex32(stored) + " does not match its bytes (" + hex32(actual) +
                          "): the extension is corrupt");
}

}  // namespace

bool needs_extension(const Tree& tree) noexcept {
  const auto& frame = tree.stored_frame();
  return (frame && frame->quantization == Quantization::grid) || !tree.georef().crs_wkt.empty() ||
         !tree.attributes().empty() || tree.payload_meaning() != PayloadMeaning::reference;
}

bool starts_extension(std::span<const std::uint8_t> bytes) noexcept {
  return bytes.size() >= 8 && std::memcmp(bytes.data(), kExtensionMagic, 8) == 0;
}

std::uint64_t ExtensionPieces::size() const noexcept {
  std::uint64_t bytes = own.size();
  for (const auto& piece : borrowed) bytes += piece.second.size();
  return bytes;
}

void append_extension(const Tree& tree, bool compress_levels, int level, bool mix_occupancy, ExtensionPieces& out) {
  ByteWriter w(out.own);
  std::uint64_t borrowed_bytes = 0;  // so far: the file offset is own.size() + this
  w.put_bytes(kExtensionMagic);
  w.put(kExtensionVersion);
  const bool meaning = tree.payload_meaning() != PayloadMeaning::reference;
  const std::uint32_t records = 1 + (tree.georef().crs_wkt.empty() ? 0 : 1) + (meaning ? 1 : 0) +
                                static_cast<std::uint32_t>(tree.attributes().size()) + (compress_levels ? 1 : 0);
  w.put(records);

  const Frame frame = tree.frame();
  begin_record(w, RecordTag::frame, 0, 40);
  w.put(static_cast<std::uint8_t>(frame.quantization));
  for (int i = 0; i < 7; ++i) w.put(std::uint8_t{0});
  for (double o : frame.origin) w.put(o);
  w.put(frame.voxel_size);

  if (!tree.georef().crs_wkt.empty()) {
    const auto& wkt = tree.georef().crs_wkt;
    begin_record(w, RecordTag::crs_wkt, 0, wkt.size());
    w.put_bytes(as_bytes(wkt));
    w.pad_to(8);
  }

  if (meaning) {
    // Before the attributes: a reader knows what the payload means before any column.
    begin_record(w, RecordTag::payload_meaning, 0, 8);
    w.put(static_cast<std::uint8_t>(tree.payload_meaning()));
    for (int i = 0; i < 7; ++i) w.put(std::uint8_t{0});
  }

  VoxelCorners corners(tree, frame);
  const auto& columns = tree.attributes().columns();
  for (std::size_t c = 0; c < columns.size(); ++c) {
    const AttributeColumn& column = columns[c];
    const auto raw = column.bytes();
    EncodedColumn encoded;
    const bool compress = compress_levels && zstd_available();
    if (compress) encoded = encode_column(column, std::span(columns.data(), c), corners, level);
    const std::vector<std::uint8_t>& packed = encoded.data;
    const std::uint64_t data_size = compress ? packed.size() : raw.size();
    begin_record(w, RecordTag::attribute, 0, 16 + column.name().size() + data_size);
    w.put(static_cast<std::uint8_t>(column.type()));
    w.put(static_cast<std::uint8_t>(column.reduction()));
    w.put(compress ? encoded.encoding : kEncodingRaw);
    w.put(std::uint8_t{0});
    w.put(static_cast<std::uint32_t>(column.name().size()));
    w.put(static_cast<std::uint64_t>(raw.size()));
    w.put_bytes(as_bytes(column.name()));
    if (compress) {
      w.put_bytes(packed);
    } else {
      out.borrowed.emplace_back(w.size(), std::span<const std::uint8_t>(reinterpret_cast<const std::uint8_t*>(raw.data()), raw.size()));
      borrowed_bytes += raw.size();
    }
    while ((w.size() + borrowed_bytes) % 8) w.put(std::uint8_t{0});  // padding by the file offset
  }

  if (compress_levels) {
    // Levels differ in statistics (a leaf level is nothing like its parents), so each
    // part gets a frame of its own: u32 parts, u32 reserved, per part u64 raw bytes and
    // u64 compressed bytes, then the frames.
    std::vector<std::span<const std::uint64_t>> parts;
    for (int l = 0; l < tree.depth(); ++l) {
      parts.push_back(tree.occupancy(l));
      if (tree.has_payload()) parts.push_back(tree.payload(l));
    }
    std::vector<std::vector<std::uint8_t>> frames;
    std::uint64_t length = 8;
    OccupancyCoder occupancy(mix_occupancy ? OccupancyCoder::Modelling::mixed : OccupancyCoder::Modelling::contexts);
    for (std::size_t p = 0; p < parts.size(); ++p) {
      const bool is_occupancy = !tree.has_payload() || p % 2 == 0;
      if (is_occupancy)
        frames.push_back(occupancy.encode(parts[p], p + (tree.has_payload() ? 2 : 1) >= parts.size()));
      else
        frames.push_back(zstd_compress(lanes16_from_words(parts[p]), level));
      length += 16 + frames.back().size();
    }
    begin_record(w, RecordTag::levels, mix_occupancy ? kMixedOccupancy : kCodedOccupancy, length);
    w.put(static_cast<std::uint32_t>(parts.size()));
    w.put(std::uint32_t{0});
    for (std::size_t p = 0; p < parts.size(); ++p) {
      w.put(static_cast<std::uint64_t>(8 * parts[p].size()));
      w.put(static_cast<std::uint64_t>(frames[p].size()));
    }
    for (const auto& compressed : frames) w.put_bytes(compressed);
    while ((w.size() + borrowed_bytes) % 8) w.put(std::uint8_t{0});
  }
  append_trailer(out);
}

namespace {

// The frame record: quantization, origin and voxel size.
Frame decode_frame(ByteReader& body, std::uint64_t record_offset, int depth) {
  Frame f;
  const auto mode = body.get<std::uint8_t>("frame quantization");
  if (mode > 1) body.fail_at(record_offset + 16, "unknown quantization mode " + std::to_string(mode));
  f.quantization = static_cast<Quantization>(mode);
  body.take(7, "frame padding");
  for (double& o : f.origin) o = body.get<double>("frame origin");
  f.voxel_size = body.get<double>("frame voxel size");
  if (!(f.voxel_size > 0.0)) body.fail_at(record_offset + 48, "voxel size is not positive");
  if (!std::isfinite(f.voxel_size)) body.fail_at(record_offset + 48, "voxel size is not finite");
  for (int a = 0; a < 3; ++a)
    if (!std::isfinite(f.origin[a]))
      body.fail_at(record_offset + 24 + 8 * static_cast<std::uint64_t>(a), "frame origin is not finite");
  // The grid's far corner too: an origin of 1e308 and voxels of 1e307 put every voxel
  // at infinity (coordinates printed as inf, a LAS export's scale search never ended).
  const double side = std::ldexp(1.0, 2 * std::max(depth, 0)) * f.voxel_size;
  for (int a = 0; a < 3; ++a)
    if (!std::isfinite(f.origin[a] + side))
      body.fail_at(record_offset + 24 + 8 * static_cast<std::uint64_t>(a),
                   "the grid's far corner (origin + voxel size x 4^depth) is not a finite number");
  return f;
}

// An attribute record: one column, zstd-compressed or plain.
AttributeColumn decode_attribute(ByteReader& body, std::uint64_t record_offset, const std::string& name,
                                 ExtensionContents& out) {
    const auto type = body.get<std::uint8_t>("attribute type");
    const auto reduction = body.get<std::uint8_t>("attribute reduction");
    const auto encoding = body.get<std::uint8_t>("attribute encoding");
    body.get<std::uint8_t>("attribute reserved byte");
    const auto name_length = body.get<std::uint32_t>("attribute name length");
    const auto raw_size = body.get<std::uint64_t>("attribute size");
    const auto column_name = body.take(name_length, "attribute name");
    if (type > 9) body.fail_at(record_offset + 16, "unknown attribute value type " + std::to_string(type));
    if (reduction > 4) body.fail_at(record_offset + 17, "unknown attribute reduction " + std::to_string(reduction));
    if (encoding > kEncodingPartnerDelta)
      body.fail_at(record_offset + 18, "unknown attribute encoding " + std::to_string(encoding));
    AttributeColumn column(std::string(column_name.begin(), column_name.end()), static_cast<ValueType>(type),
                           static_cast<Reduction>(reduction));
    if (raw_size % size_of(column.type()) != 0)
      body.fail_at(record_offset + 24, "attribute size " + std::to_string(raw_size) +
                                           " is not a whole number of values");
    const auto data = body.take(body.remaining(), "attribute data");
    std::vector<std::uint8_t> raw;
    if (encoding >= kEncodingDeltaPlanes) {  // needs the tree: decoded later
      check_ratio(body, raw_size, data.size());
      out.pending.push_back({out.attributes.size(), encoding, raw_size, data, record_offset + 32 + name_length});
      return column;
    }
    if (encoding == kEncodingZstd) {
      check_ratio(body, raw_size, data.size());
      raw = zstd_decompress(data, raw_size, name, record_offset + 32 + name_length);
    } else {
      if (data.size() != raw_size)
        body.fail_at(record_offset + 24, "attribute holds " + std::to_string(data.size()) +
                                             " bytes, its header says " + std::to_string(raw_size));
      raw.assign(data.begin(), data.end());
    }
    column.resize(raw_size / size_of(column.type()));
    if (!raw.empty()) std::memcpy(column.bytes().data(), raw.data(), raw.size());
  return column;
}

// The zstd-compressed levels record: parts of 16-bit lanes, into out.levels.
void decode_levels(ByteReader& body, std::uint64_t record_offset, std::uint32_t flags, const std::string& name,
                   int depth, bool payload, ExtensionContents& out) {
    if (flags != kLanes16PerPart && flags != kCodedOccupancy && flags != kMixedOccupancy)
      body.fail_at(record_offset + 4, "compressed levels in an unknown layout (flags " + std::to_string(flags) + ")");
    const auto parts = body.get<std::uint32_t>("level part count");
    // Each coded level costs its models' memory however small its part: a file may not
    // claim more levels than its header's depth.
    const std::uint64_t most = static_cast<std::uint64_t>(std::max(depth, 0)) * (payload ? 2 : 1);
    if (parts > most)
      body.fail_at(record_offset + 16, std::to_string(parts) + " level parts for a tree of depth " +
                                           std::to_string(depth) + (payload ? " with payload" : "") + " (at most " +
                                           std::to_string(most) + ")");
    body.get<std::uint32_t>("reserved");
    body.need(16 * std::uint64_t{parts}, "level part sizes");
    std::vector<std::pair<std::uint64_t, std::uint64_t>> sizes(parts);
    std::uint64_t raw_total = 0, packed_total = 0;
    for (auto& [raw, packed] : sizes) {
      raw = body.get<std::uint64_t>("level part size");
      packed = body.get<std::uint64_t>("level part compressed size");
      if (raw % 8 != 0) body.fail("level part size " + std::to_string(raw) + " is not a whole number of words");
      check_ratio(body, raw, packed);
      if (raw > (std::uint64_t{1} << 62) || packed > body.remaining())
        body.fail("level part of " + std::to_string(packed) + " compressed bytes runs past the record");
      raw_total += raw;
      packed_total += packed;
    }
    if (packed_total != body.remaining())
      body.fail("level parts take " + std::to_string(packed_total) + " bytes, the record holds " +
                std::to_string(body.remaining()));
    // Coded occupancy: the parts alternate occupancy and payload when there is payload,
    // which only the header says; the part count tells (one part per level, or two).
    const bool coded = flags == kCodedOccupancy || flags == kMixedOccupancy;
    const bool with_payload = coded && payload;
    if (with_payload && parts % 2 != 0)
      body.fail_at(record_offset + 16, "levels with payload in an odd number of parts (" + std::to_string(parts) + ")");
    out.levels.resize(raw_total / 8);
    std::size_t at = 0;
    OccupancyCoder occupancy(flags == kMixedOccupancy ? OccupancyCoder::Modelling::mixed
                                                      : OccupancyCoder::Modelling::contexts);
    for (std::uint32_t p = 0; p < parts; ++p) {
      const auto [raw, packed] = sizes[p];
      const std::uint64_t frame_offset = body.offset();
      const auto frame = body.take(packed, "level part");
      const auto words = std::span<std::uint64_t>(out.levels).subspan(at, raw / 8);
      if (coded && (!with_payload || p % 2 == 0)) {
        const std::uint32_t next = p + (with_payload ? 2 : 1);
        const bool last = next >= parts;
        occupancy.decode(frame, words, last, last ? 0 : sizes[next].first / 8, name, frame_offset);
      } else {
        const auto lanes = zstd_decompress(frame, raw, name, frame_offset);
        words_from_lanes16(lanes, words);
      }
      at += raw / 8;
    }
  out.has_levels = true;
  out.compressed_level_bytes = packed_total;
  out.level_layout = flags;
}

}  // namespace

ExtensionContents decode_extension(std::span<const std::uint8_t> bytes, const std::string& name,
                                   std::uint64_t base, int depth, bool payload) {
  ByteReader r(bytes, name, base);
  const auto magic = r.take(8, "extension magic");
  if (std::memcmp(magic.data(), kExtensionMagic, 8) != 0)
    r.fail_at(base, "bytes after the levels are neither nothing nor a vola extension");
  ExtensionContents out;
  out.version = r.get<std::uint32_t>("extension version");
  if (out.version == 0 || out.version > kExtensionVersion)
    r.fail_at(base + 8, "extension version " + std::to_string(out.version) +
                            " is not known to this vola (knows 1.." + std::to_string(kExtensionVersion) + ")");
  const auto records = r.get<std::uint32_t>("extension record count");
  std::unordered_set<std::string> attribute_names;  // one search per name made 80,000 columns take seconds
  bool seen_crs = false;
  for (std::uint32_t i = 0; i < records; ++i) {
    const std::uint64_t record_offset = r.offset();
    const auto tag = r.get<std::uint32_t>("record tag");
    const auto flags = r.get<std::uint32_t>("record flags");
    const auto length = r.get<std::uint64_t>("record length");
    ByteReader body(r.take(length, "record body"), name, record_offset + 16);
    r.skip_padding(8);
    switch (static_cast<RecordTag>(tag)) {
      case RecordTag::frame:
        // One of each: a second frame or CRS record silently replaced the first.
        if (out.frame) body.fail_at(record_offset, "a second frame record (a file holds one)");
        out.frame = decode_frame(body, record_offset, depth);
        break;
      case RecordTag::crs_wkt: {
        if (seen_crs) body.fail_at(record_offset, "a second CRS record (a file holds one)");
        seen_crs = true;
        const auto text = body.take(length, "CRS WKT");
        // A NUL ends the text for PROJ: "EPSG:4326\0junk" read as EPSG:4326.
        if (const auto nul = std::find(text.begin(), text.end(), std::uint8_t{0}); nul != text.end())
          body.fail_at(record_offset + 16 + static_cast<std::uint64_t>(nul - text.begin()),
                       "the CRS text holds a NUL byte");
        out.crs_wkt.assign(text.begin(), text.end());
        break;
      }
      case RecordTag::attribute: {
        AttributeColumn column = decode_attribute(body, record_offset, name, out);
        if (!attribute_names.insert(column.name()).second)
          body.fail_at(record_offset, "attribute '" + column.name() + "' appears twice");
        out.attributes.push_back(std::move(column));
        break;
      }
      case RecordTag::levels:
        decode_levels(body, record_offset, flags, name, depth, payload, out);
        break;
      case RecordTag::payload_meaning: {
        const auto meaning = body.get<std::uint8_t>("payload meaning");
        if (meaning > static_cast<std::uint8_t>(PayloadMeaning::occupancy_state))
          body.fail_at(record_offset + 16, "unknown payload meaning " + std::to_string(meaning) +
                                               " (this vola knows 0 reference, 1 occupancy state)");
        out.payload_meaning = static_cast<PayloadMeaning>(meaning);
        out.payload_meaning_offset = record_offset;
        break;
      }
      default:
        break;  // a record of a later version: skipped
    }
  }
  if (out.version >= kFirstVersionWithTrailer) check_trailer(r, bytes, base);
  if (r.remaining() != 0)
    r.fail(std::to_string(r.remaining()) + " bytes follow the last extension record");
  return out;
}

void decode_pending_columns(ExtensionContents& ext, const Tree& tree, const std::string& name) {
  VoxelCorners corners(tree, tree.frame());
  for (const auto& p : ext.pending) {
    AttributeColumn& column = ext.attributes[p.index];
    const std::uint64_t values = p.raw_size / size_of(column.type());
    if (values != tree.voxel_count())
      VOLA_THROW(FormatError(name, p.offset,
                             "attribute '" + column.name() + "' has " + std::to_string(values) + " values for " +
                                 std::to_string(tree.voxel_count()) + " voxels"));
    column.resize(values);
    decode_column(p.encoding, p.data, column, std::span(ext.attributes.data(), p.index), corners, name, p.offset);
  }
  ext.pending.clear();
}

}  // namespace detail
VOLA_INLINE_NAMESPACE_END
}  // namespace vola
