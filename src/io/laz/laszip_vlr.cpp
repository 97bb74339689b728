// The laszip VLR (record 22204 of user "laszip encoded") and the item sequences the
// codec supports.
#include <cstring>
#include <string>
#include <utility>

#include "record_layout.hpp"
#include "vola/error.hpp"
#include "vola/little_endian.hpp"

namespace vola::io::laz {
namespace {

constexpr std::size_t kFixedBytes = 34;  // the fields before the item list
constexpr std::size_t kItemBytes = 6;

const char* item_name(std::uint16_t type) {
  switch (type) {
    case kByte: return "BYTE";
    case kPoint10: return "POINT10";
    case kGpsTime11: return "GPSTIME11";
    case kRgb12: return "RGB12";
    case kWavePacket13: return "WAVEPACKET13";
    case kPoint14: return "POINT14";
    case kRgb14: return "RGB14";
    case kRgbNir14: return "RGBNIR14";
    case kWavePacket14: return "WAVEPACKET14";
    case kByte14: return "BYTE14";
    default: return nullptr;
  }
}


// Walks the item list in the fixed order of a record's parts.
class ItemCursor {
 public:
  ItemCursor(const LaszipInfo& info, const std::string& source, std::uint64_t items_offset)
      : info_(info), source_(source), items_offset_(items_offset) {}

  // The next item when it has `type`; checks its size (0 = any non-zero) and version.
  const Item* take(std::uint16_t type, std::uint16_t size, bool layered) {
    if (at_ == info_.items.size() || info_.items[at_].type != type) return nullptr;
    const Item& item = info_.items[at_];
    if (size ? item.size != size : item.size == 0) fail(describe_item(item) + " has the wrong size");
    // LASzip defines WAVEPACKET13 in version 1 only, the other point-wise items in
    // versions 1 (LASzip 1.x) and 2.
    const bool supported = layered                    ? (item.version == 3 || item.version == 4)
                           : item.type == kWavePacket13 ? item.version == 1
                                                        : (item.version == 1 || item.version == 2);
    if (!supported)
      fail(describe_item(item) +
           " is not supported (point-wise items need version 1 or 2, wave packets 1; layered items 3 or 4)");
    ++at_;
    return &item;
  }
  void finish() {
    if (at_ != info_.items.size())
      fail(describe_item(info_.items[at_]) + " cannot follow the items before it (compressor " +
           std::to_string(info_.compressor) + ")");
  }
  [[noreturn]] void fail(const std::string& cause) const {
    VOLA_THROW(FormatError(source_, items_offset_ + kItemBytes * at_, "laszip record: " + cause));
  }

 private:
  const LaszipInfo& info_;
  const std::string& source_;
  std::uint64_t items_offset_;
  std::size_t at_ = 0;
};

}  // namespace

std::string describe_item(const Item& item) {
  const char* name = item_name(item.type);
  return (name ? std::string(name) : "item type " + std::to_string(item.type)) + "(" + std::to_string(item.size) +
         ") version " + std::to_string(item.version);
}

std::size_t LaszipInfo::record_length() const {
  std::size_t n = 0;
  for (const Item& item : items) n += item.size;
  return n;
}

RecordLayout record_layout(const LaszipInfo& info, const std::string& source, std::uint64_t items_offset) {
  ItemCursor cursor(info, source, items_offset);
  if (info.coder != 0) cursor.fail("coder " + std::to_string(info.coder) + " is unknown (0 = arithmetic)");
  RecordLayout layout;
  layout.layered = info.compressor == 3;
  if (info.compressor < 1 || info.compressor > 3)
    cursor.fail("compressor " + std::to_string(info.compressor) + " is not one of 1, 2, 3");
  if (!layout.layered) {
    const Item* point = cursor.take(kPoint10, 20, false);
    if (!point) cursor.fail("point-wise records must start with POINT10");
    layout.point_v1 = point->version == 1;
    layout.length = 20;
    if (const Item* gps = cursor.take(kGpsTime11, 8, false)) {
      layout.gps_at = std::exchange(layout.length, layout.length + 8);
      layout.gps_v1 = gps->version == 1;
    }
    if (const Item* rgb = cursor.take(kRgb12, 6, false)) {
      layout.rgb_at = std::exchange(layout.length, layout.length + 6);
      layout.rgb_v1 = rgb->version == 1;
    }
    if (cursor.take(kWavePacket13, 29, false)) layout.wave_at = std::exchange(layout.length, layout.length + 29);
    if (const Item* bytes = cursor.take(kByte, 0, false)) {
      layout.bytes_at = layout.length;
      layout.bytes = bytes->size;
      layout.bytes_v1 = bytes->version == 1;
      layout.length += bytes->size;
    }
  } else {
    const Item* point = cursor.take(kPoint14, 30, true);
    if (!point) cursor.fail("layered records must start with POINT14");
    layout.point_v4 = point->version == 4;
    layout.length = 30;
    layout.gps_at = 22;
    const Item* rgb = cursor.take(kRgb14, 6, true);
    if (!rgb && (rgb = cursor.take(kRgbNir14, 8, true))) layout.nir = true;
    if (rgb) {
      layout.rgb_at = 30;
      layout.rgb_v4 = rgb->version == 4;
      layout.length += rgb->size;
    }
    if (const Item* wave = cursor.take(kWavePacket14, 29, true)) {
      layout.wave_at = std::exchange(layout.length, layout.length + 29);
      layout.wave_v4 = wave->version == 4;
    }
    if (const Item* bytes = cursor.take(kByte14, 0, true)) {
      layout.bytes_at = layout.length;
      layout.bytes = bytes->size;
      layout.bytes_v4 = bytes->version == 4;
      layout.length += bytes->size;
    }
  }
  cursor.finish();
  return layout;
}

LaszipInfo parse_laszip_vlr(std::span<const std::uint8_t> payload, const std::string& source,
                            std::uint64_t payload_offset) {
  if (payload.size() < kFixedBytes)
    VOLA_THROW(FormatError(source, payload_offset,
                           "laszip record has " + std::to_string(payload.size()) + " bytes, fewer than 34"));
  const std::uint8_t* p = payload.data();
  LaszipInfo info;
  info.compressor = load_le<std::uint16_t>(p);
  info.coder = load_le<std::uint16_t>(p + 2);
  info.version_major = p[4];
  info.version_minor = p[5];
  info.revision = load_le<std::uint16_t>(p + 6);
  info.options = load_le<std::uint32_t>(p + 8);
  info.chunk_size = load_le<std::uint32_t>(p + 12);
  info.special_evlr_count = load_le<std::int64_t>(p + 16);
  info.special_evlr_offset = load_le<std::int64_t>(p + 24);
  const std::size_t count = load_le<std::uint16_t>(p + 32);
  if (payload.size() < kFixedBytes + kItemBytes * count)
    VOLA_THROW(FormatError(source, payload_offset + 32,
                           "laszip record lists " + std::to_string(count) + " items but holds " +
                               std::to_string((payload.size() - kFixedBytes) / kItemBytes)));
  for (std::size_t i = 0; i < count; ++i) {
    const std::uint8_t* q = p + kFixedBytes + kItemBytes * i;
    info.items.push_back({load_le<std::uint16_t>(q), load_le<std::uint16_t>(q + 2), load_le<std::uint16_t>(q + 4)});
  }
  record_layout(info, source, payload_offset + kFixedBytes);
  return info;
}

std::vector<std::uint8_t> laszip_vlr_payload(const LaszipInfo& info) {
  std::vector<std::uint8_t> out(kFixedBytes + kItemBytes * info.items.size());
  auto put = [&out](std::size_t at, auto value) { std::memcpy(out.data() + at, &value, sizeof value); };
  put(0, info.compressor);
  put(2, info.coder);
  out[4] = info.version_major;
  out[5] = info.version_minor;
  put(6, info.revision);
  put(8, info.options);
  put(12, info.chunk_size);
  put(16, info.special_evlr_count);
  put(24, info.special_evlr_offset);
  put(32, static_cast<std::uint16_t>(info.items.size()));
  for (std::size_t i = 0; i < info.items.size(); ++i) {
    const std::size_t at = kFixedBytes + kItemBytes * i;
    put(at, info.items[i].type);
    put(at + 2, info.items[i].size);
    put(at + 4, info.items[i].version);
  }
  return out;
}

LaszipInfo laszip_info_for(std::uint8_t point_format, std::uint16_t record_length) {
  static constexpr std::uint16_t kBase[] = {20, 28, 26, 34, 57, 63, 30, 36, 38, 59, 67};
  if (point_format > 10)
    VOLA_THROW(InvalidArgument("LAZ: point format " + std::to_string(point_format) + " is unknown (0-10)"));
  const std::uint16_t base = kBase[point_format];
  if (record_length < base)
    VOLA_THROW(InvalidArgument("LAZ: record length " + std::to_string(record_length) + " is below format " +
                               std::to_string(point_format) + "'s " + std::to_string(base)));
  LaszipInfo info;
  const std::uint16_t extra = record_length - base;
  if (point_format <= 5) {
    info.compressor = 2;
    info.items.push_back({kPoint10, 20, 2});
    if (point_format != 0 && point_format != 2) info.items.push_back({kGpsTime11, 8, 2});
    if (point_format == 2 || point_format == 3 || point_format == 5) info.items.push_back({kRgb12, 6, 2});
    if (point_format >= 4) info.items.push_back({kWavePacket13, 29, 1});
    if (extra) info.items.push_back({kByte, extra, 2});
  } else {
    info.compressor = 3;
    info.items.push_back({kPoint14, 30, 3});
    if (point_format == 7) info.items.push_back({kRgb14, 6, 3});
    if (point_format == 8 || point_format == 10) info.items.push_back({kRgbNir14, 8, 3});
    if (point_format >= 9) info.items.push_back({kWavePacket14, 29, 3});
    if (extra) info.items.push_back({kByte14, extra, 3});
  }
  return info;
}

}  // namespace vola::io::laz
