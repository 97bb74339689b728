// Compressor 1 and 2 chunks: the chunk's first record stored raw (it seeds every item's
// "last" values), then a single arithmetic stream with the other records' items in
// record order. Items of version 1 or 2 (pointwise_items_v1.hpp, pointwise_items.hpp).
#include <memory>
#include <optional>

#include "pointwise_items.hpp"
#include "pointwise_items_v1.hpp"
#include "record_layout.hpp"

namespace vola::io::laz {
namespace {

// The coders of one record layout; optional parts exist only when the record has them,
// so the per-point loop tests a flag instead of calling through a table. Each item is
// coded by its version's coder (version 1: LASzip 1.x files).
struct PointwiseCoders {
  PointwiseCoders(const RecordLayout& record, bool decoding) : layout(record) {
    if (layout.point_v1) point_v1.emplace(decoding);
    else point.emplace(decoding);
    if (layout.gps_at && layout.gps_v1) gps_v1.emplace(decoding);
    else if (layout.gps_at) gps.emplace(decoding);
    if (layout.rgb_at && layout.rgb_v1) rgb_v1.emplace(decoding);
    else if (layout.rgb_at) rgb.emplace(decoding);
    if (layout.wave_at) wave.emplace(decoding);
    if (layout.bytes && layout.bytes_v1) bytes_v1.emplace(layout.bytes, decoding);
    else if (layout.bytes) bytes.emplace(layout.bytes, decoding);
  }
  void start(const std::uint8_t* first) {
    if (point) point->start(first);
    if (point_v1) point_v1->start(first);
    if (gps) gps->start(first + layout.gps_at);
    if (gps_v1) gps_v1->start(first + layout.gps_at);
    if (rgb) rgb->start(first + layout.rgb_at);
    if (rgb_v1) rgb_v1->start(first + layout.rgb_at);
    if (wave) wave->start(first + layout.wave_at);
    if (bytes) bytes->start(first + layout.bytes_at);
    if (bytes_v1) bytes_v1->start(first + layout.bytes_at);
  }
  // Any mix of versions, item by item (the version 2 loop below is the fast one).
  void decode_any_version(ArithmeticDecoder& d, std::uint8_t* out) {
    if (point) point->decode(d, out);
    else point_v1->decode(d, out);
    if (gps) gps->decode(d, out + layout.gps_at);
    if (gps_v1) gps_v1->decode(d, out + layout.gps_at);
    if (rgb) rgb->decode(d, out + layout.rgb_at);
    if (rgb_v1) rgb_v1->decode(d, out + layout.rgb_at);
    if (wave) wave->decode(d, out + layout.wave_at);
    if (bytes) bytes->decode(d, out + layout.bytes_at);
    if (bytes_v1) bytes_v1->decode(d, out + layout.bytes_at);
  }
  void encode(ArithmeticEncoder& e, const std::uint8_t* in) {
    if (point) point->encode(e, in);
    else point_v1->encode(e, in);
    if (gps) gps->encode(e, in + layout.gps_at);
    if (gps_v1) gps_v1->encode(e, in + layout.gps_at);
    if (rgb) rgb->encode(e, in + layout.rgb_at);
    if (rgb_v1) rgb_v1->encode(e, in + layout.rgb_at);
    if (wave) wave->encode(e, in + layout.wave_at);
    if (bytes) bytes->encode(e, in + layout.bytes_at);
    if (bytes_v1) bytes_v1->encode(e, in + layout.bytes_at);
  }

  std::optional<Point10Coder> point;
  std::optional<Point10V1Coder> point_v1;
  std::optional<GpsTime11Coder> gps;
  std::optional<GpsTime11V1Coder> gps_v1;
  std::optional<Rgb12Coder> rgb;
  std::optional<Rgb12V1Coder> rgb_v1;
  std::optional<WavePacket13Coder> wave;
  std::optional<ByteCoder> bytes;
  std::optional<ByteV1Coder> bytes_v1;
  RecordLayout layout;
};

// The coders of the last layout this thread used: a file's chunks share one set, so a
// chunk costs a reset, not the allocation of its models (COPC files have many small
// chunks). Held on the heap: the state is large and a decoder may run on a small stack.
PointwiseCoders& pointwise_coders_for(const RecordLayout& layout, bool decoding) {
  thread_local std::unique_ptr<PointwiseCoders> cached[2];
  auto& coders = cached[decoding ? 1 : 0];
  if (!coders || !(coders->layout == layout)) coders = std::make_unique<PointwiseCoders>(layout, decoding);
  return *coders;
}

}  // namespace

std::uint64_t decode_pointwise_chunk(const RecordLayout& layout, std::span<const std::uint8_t> chunk,
                                     std::uint64_t count, std::uint8_t* records) {
  if (count == 0) return 0;
  const std::size_t n = layout.length;
  if (chunk.size() < n) return n - chunk.size();
  std::memcpy(records, chunk.data(), n);
  if (count == 1) return 0;
  PointwiseCoders& coders = pointwise_coders_for(layout, true);
  coders.start(records);
  ArithmeticDecoder d(chunk.subspan(n));
  std::uint8_t* out = records + n;
  if (layout.any_v1()) {
    for (std::uint64_t i = 1; i < count; ++i, out += n) {
      coders.decode_any_version(d, out);
      if (d.overrun() > 4) return d.overrun();
    }
    return d.overrun();
  }
  Point10Coder& point = *coders.point;
  GpsTime11Coder* gps = coders.gps ? &*coders.gps : nullptr;
  Rgb12Coder* rgb = coders.rgb ? &*coders.rgb : nullptr;
  WavePacket13Coder* wave = coders.wave ? &*coders.wave : nullptr;
  ByteCoder* bytes = coders.bytes ? &*coders.bytes : nullptr;
  for (std::uint64_t i = 1; i < count; ++i, out += n) {
    point.decode(d, out);
    if (gps) gps->decode(d, out + layout.gps_at);
    if (rgb) rgb->decode(d, out + layout.rgb_at);
    if (wave) wave->decode(d, out + layout.wave_at);
    if (bytes) bytes->decode(d, out + layout.bytes_at);
    // A stream that ran dry stays dry: stop early rather than decode zeros.
    if (d.overrun() > 4) return d.overrun();
  }
  return d.overrun();
}

void encode_pointwise_chunk(const RecordLayout& layout, std::span<const std::uint8_t> records,
                            std::vector<std::uint8_t>& out) {
  const std::size_t n = layout.length;
  const std::size_t count = records.size() / n;
  if (count == 0) return;
  out.insert(out.end(), records.begin(), records.begin() + static_cast<std::ptrdiff_t>(n));
  PointwiseCoders& coders = pointwise_coders_for(layout, false);
  coders.start(records.data());
  ArithmeticEncoder e;
  for (std::size_t i = 1; i < count; ++i) {
    coders.encode(e, records.data() + i * n);
  }
  e.finish();
  out.insert(out.end(), e.bytes().begin(), e.bytes().end());
}

}  // namespace vola::io::laz
