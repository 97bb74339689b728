// Compressor 1 and 2 chunks: the chunk's first record stored raw (it seeds every item's
// "last" values), then a single arithmetic stream with the other records' items in
// record order.
#include <memory>
#include <optional>

#include "pointwise_items.hpp"
#include "record_layout.hpp"

namespace vola::io::laz {
namespace {

// The coders of one record layout; optional parts exist only when the record has them,
// so the per-point loop tests a flag instead of calling through a table.
struct PointwiseCoders {
  PointwiseCoders(const RecordLayout& record, bool decoding) : point(decoding), layout(record) {
    if (layout.gps_at) gps.emplace(decoding);
    if (layout.rgb_at) rgb.emplace(decoding);
    if (layout.wave_at) wave.emplace(decoding);
    if (layout.bytes) bytes.emplace(layout.bytes, decoding);
  }
  void start(const std::uint8_t* first) {
    point.start(first);
    if (gps) gps->start(first + layout.gps_at);
    if (rgb) rgb->start(first + layout.rgb_at);
    if (wave) wave->start(first + layout.wave_at);
    if (bytes) bytes->start(first + layout.bytes_at);
  }

  Point10Coder point;
  std::optional<GpsTime11Coder> gps;
  std::optional<Rgb12Coder> rgb;
  std::optional<WavePacket13Coder> wave;
  std::optional<ByteCoder> bytes;
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
  Point10Coder& point = coders.point;
  GpsTime11Coder* gps = coders.gps ? &*coders.gps : nullptr;
  Rgb12Coder* rgb = coders.rgb ? &*coders.rgb : nullptr;
  WavePacket13Coder* wave = coders.wave ? &*coders.wave : nullptr;
  ByteCoder* bytes = coders.bytes ? &*coders.bytes : nullptr;
  std::uint8_t* out = records + n;
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
    const std::uint8_t* in = records.data() + i * n;
    coders.point.encode(e, in);
    if (coders.gps) coders.gps->encode(e, in + layout.gps_at);
    if (coders.rgb) coders.rgb->encode(e, in + layout.rgb_at);
    if (coders.wave) coders.wave->encode(e, in + layout.wave_at);
    if (coders.bytes) coders.bytes->encode(e, in + layout.bytes_at);
  }
  e.finish();
  out.insert(out.end(), e.bytes().begin(), e.bytes().end());
}

}  // namespace vola::io::laz
