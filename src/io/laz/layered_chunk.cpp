// Compressor 3 chunks:
//   the first record, raw
//   uint32  number of points in the chunk (the first included)
//   uint32  byte size of each layer: POINT14's 9, then RGB (1) or RGBNIR (2), then the
//           wave packets (1), then one per extra byte
//   the layers' bytes in the same order
#include <cstring>
#include <memory>
#include <optional>
#include <string>

#include "layered_items.hpp"
#include "record_layout.hpp"
#include "vola/error.hpp"
#include "vola/little_endian.hpp"

namespace vola::io::laz {
namespace {

std::size_t layer_count(const RecordLayout& layout) {
  return kLayers14 + (layout.rgb_at ? (layout.nir ? 2 : 1) : 0) + (layout.wave_at ? 1 : 0) + layout.bytes;
}

struct LayeredCoders {
  LayeredCoders(const RecordLayout& record, bool decoding) : point(decoding, record.point_v4), layout(record) {
    if (layout.rgb_at) rgb.emplace(decoding, layout.nir, layout.rgb_v4);
    if (layout.wave_at) wave.emplace(decoding, layout.wave_v4);
    if (layout.bytes) bytes.emplace(layout.bytes, decoding, layout.bytes_v4);
  }
  void start(const std::uint8_t* first) {
    const std::uint32_t context = point.start(first);
    if (rgb) rgb->start(first + layout.rgb_at, context);
    if (wave) wave->start(first + layout.wave_at, context);
    if (bytes) bytes->start(first + layout.bytes_at, context);
  }
  Point14Coder point;
  std::optional<Rgb14Coder> rgb;
  std::optional<WavePacket14Coder> wave;
  std::optional<Byte14Coder> bytes;
  RecordLayout layout;
};

// As for point-wise chunks: the last layout's coders are kept per thread, so that the
// many small chunks of a COPC file do not each allocate their models.
LayeredCoders& layered_coders_for(const RecordLayout& layout, bool decoding) {
  thread_local std::unique_ptr<LayeredCoders> cached[2];
  auto& coders = cached[decoding ? 1 : 0];
  if (!coders || !(coders->layout == layout)) coders = std::make_unique<LayeredCoders>(layout, decoding);
  return *coders;
}

// Splits the chunk's layer bytes; throws when the sizes do not fit the chunk.
std::vector<std::span<const std::uint8_t>> split_layers(const RecordLayout& layout, std::span<const std::uint8_t> chunk,
                                                        std::uint64_t count, const std::string& where,
                                                        std::uint64_t chunk_offset, const std::string& source) {
  const std::size_t layers = layer_count(layout);
  const std::size_t head = layout.length + 4 + 4 * layers;
  if (chunk.size() < head)
    VOLA_THROW(FormatError(source, chunk_offset + chunk.size(),
                           "LAZ " + where + " of " + std::to_string(chunk.size()) + " bytes is too short for its header of " +
                               std::to_string(head)));
  const auto stated = load_le<std::uint32_t>(chunk.data() + layout.length);
  if (stated != count)
    VOLA_THROW(FormatError(source, chunk_offset + layout.length,
                           "LAZ " + where + " says it holds " + std::to_string(stated) + " points, the chunk table " +
                               std::to_string(count)));
  std::vector<std::span<const std::uint8_t>> spans(layers);
  std::uint64_t at = head;
  for (std::size_t i = 0; i < layers; ++i) {
    const std::uint64_t size = load_le<std::uint32_t>(chunk.data() + layout.length + 4 + 4 * i);
    if (size > chunk.size() - at)
      VOLA_THROW(FormatError(source, chunk_offset + layout.length + 4 + 4 * i,
                             "LAZ " + where + ": layer " + std::to_string(i) + " of " + std::to_string(size) +
                                 " bytes runs past the chunk's end"));
    spans[i] = chunk.subspan(static_cast<std::size_t>(at), static_cast<std::size_t>(size));
    at += size;
  }
  return spans;
}

}  // namespace

std::uint64_t decode_layered_chunk(const RecordLayout& layout, std::span<const std::uint8_t> chunk,
                                   std::uint64_t count, std::uint8_t* records, const std::string& where,
                                   std::uint64_t chunk_offset, const std::string& source, bool xyz_only) {
  if (count == 0) return 0;
  const std::size_t n = layout.length;
  const auto spans = split_layers(layout, chunk, count, where, chunk_offset, source);
  std::memcpy(records, chunk.data(), n);
  if (count == 1) return 0;
  LayeredCoders* coders = &layered_coders_for(layout, true);
  coders->start(records);
  std::array<std::span<const std::uint8_t>, kLayers14> point_layers;
  std::copy(spans.begin(), spans.begin() + kLayers14, point_layers.begin());
  coders->point.set_layers(point_layers, xyz_only);
  if (xyz_only) {
    // The items after POINT14 are not decoded: their bytes repeat the first record's.
    constexpr std::size_t kPoint14Bytes = 30;
    std::uint8_t* out = records + n;
    for (std::uint64_t i = 1; i < count; ++i, out += n) {
      coders->point.decode(out);
      if (n > kPoint14Bytes) std::memcpy(out + kPoint14Bytes, records + kPoint14Bytes, n - kPoint14Bytes);
    }
    return coders->point.overrun();
  }
  std::size_t next = kLayers14;
  if (coders->rgb) {
    coders->rgb->set_layers(spans[next], layout.nir ? spans[next + 1] : std::span<const std::uint8_t>{});
    next += layout.nir ? 2 : 1;
  }
  if (coders->wave) coders->wave->set_layer(spans[next++]);
  if (coders->bytes) coders->bytes->set_layers(std::span(spans).subspan(next));
  Rgb14Coder* rgb = coders->rgb ? &*coders->rgb : nullptr;
  WavePacket14Coder* wave = coders->wave ? &*coders->wave : nullptr;
  Byte14Coder* bytes = coders->bytes ? &*coders->bytes : nullptr;
  std::uint8_t* out = records + n;
  for (std::uint64_t i = 1; i < count; ++i, out += n) {
    const std::uint32_t context = coders->point.decode(out);
    if (rgb) rgb->decode(context, out + layout.rgb_at);
    if (wave) wave->decode(context, out + layout.wave_at);
    if (bytes) bytes->decode(context, out + layout.bytes_at);
  }
  return coders->point.overrun() + (rgb ? rgb->overrun() : 0) + (wave ? wave->overrun() : 0) +
         (bytes ? bytes->overrun() : 0);
}

void encode_layered_chunk(const RecordLayout& layout, std::span<const std::uint8_t> records,
                          std::vector<std::uint8_t>& out) {
  const std::size_t n = layout.length;
  const std::size_t count = records.size() / n;
  if (count == 0) return;
  LayeredCoders* coders = &layered_coders_for(layout, false);
  coders->start(records.data());
  for (std::size_t i = 1; i < count; ++i) {
    const std::uint8_t* in = records.data() + i * n;
    const std::uint32_t context = coders->point.encode(in);
    if (coders->rgb) coders->rgb->encode(context, in + layout.rgb_at);
    if (coders->wave) coders->wave->encode(context, in + layout.wave_at);
    if (coders->bytes) coders->bytes->encode(context, in + layout.bytes_at);
  }
  std::vector<std::vector<std::uint8_t>> layers;
  for (auto& layer : coders->point.finish()) layers.push_back(std::move(layer));
  if (coders->rgb) {
    auto rgb = coders->rgb->finish();
    layers.push_back(std::move(rgb[0]));
    if (layout.nir) layers.push_back(std::move(rgb[1]));
  }
  if (coders->wave) layers.push_back(coders->wave->finish());
  if (coders->bytes)
    for (auto& layer : coders->bytes->finish()) layers.push_back(std::move(layer));
  out.insert(out.end(), records.begin(), records.begin() + static_cast<std::ptrdiff_t>(n));
  auto put32 = [&out](std::uint64_t v) {
    const auto w = static_cast<std::uint32_t>(v);
    const auto* p = reinterpret_cast<const std::uint8_t*>(&w);
    out.insert(out.end(), p, p + 4);
  };
  put32(count);
  for (const auto& layer : layers) put32(layer.size());
  for (const auto& layer : layers) out.insert(out.end(), layer.begin(), layer.end());
}

}  // namespace vola::io::laz
