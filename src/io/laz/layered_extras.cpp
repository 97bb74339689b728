// RGB14, RGBNIR14, WAVEPACKET14 and BYTE14 (versions 3 and 4): colour, near infrared,
// wave packets and extra bytes of LAS 1.4 records, each in its own layer(s), with models
// per scanner channel.
#include <cstring>

#include "layered_items.hpp"
#include "wave_packet_coder.hpp"

namespace vola::io::laz {
namespace {

// The context whose last values predict this point, for the items that follow
// POINT14's scanner channel. Switching to a new context seeds it from the current one;
// switching back to a known one keeps predicting from the current one's values in
// version 3 (as LASzip 3.x writes), from its own in version 4. `make` creates a context.
template <class Context, class Make>
Context& follow_channel(std::array<std::unique_ptr<Context>, 4>& contexts, std::uint32_t& current,
                        std::uint32_t context, bool version4, const Make& make) {
  Context* owner = contexts[current].get();
  if (context == current) return *owner;
  current = context;
  auto& next = contexts[current];
  if (!next) next = make();
  if (!next->used) {
    next->start_from(*owner);
    return *next;
  }
  return version4 ? *next : *owner;
}

}  // namespace

struct Rgb14Coder::Context {
  explicit Context(bool decoding) {
    rgb.create(decoding);
    nir_used.create(4, decoding);
    for (auto& m : nir_diff) m.create(256, decoding);
  }
  void start(const std::uint16_t seed[4]) {
    rgb.reset();
    nir_used.reset();
    for (auto& m : nir_diff) m.reset();
    std::memcpy(last, seed, sizeof last);
    used = true;
  }
  void start_from(const Context& other) { start(other.last); }
  bool used = false;
  std::uint16_t last[4] = {};
  RgbModels rgb;
  SymbolModel nir_used, nir_diff[2];
};

Rgb14Coder::Rgb14Coder(bool decoding, bool nir, bool version4) : decoding_(decoding), nir_(nir), version4_(version4) {}
Rgb14Coder::~Rgb14Coder() = default;

void Rgb14Coder::start(const std::uint8_t* first, std::uint32_t context) {
  for (auto& c : contexts_)
    if (c) c->used = false;
  std::uint16_t seed[4] = {};
  load_u16s(first, seed, nir_ ? 4 : 3);
  current_ = context;
  if (!contexts_[current_]) contexts_[current_] = std::make_unique<Context>(decoding_);
  contexts_[current_]->start(seed);
  for (auto& e : encoders_) e.clear();
  changed_[0] = changed_[1] = false;
}

Rgb14Coder::Context& Rgb14Coder::follow(std::uint32_t context) {
  return follow_channel(contexts_, current_, context, version4_, [&] { return std::make_unique<Context>(decoding_); });
}

void Rgb14Coder::set_layers(std::span<const std::uint8_t> rgb, std::span<const std::uint8_t> nir) {
  present_[0] = !rgb.empty();
  present_[1] = nir_ && !nir.empty();
  if (present_[0]) decoders_[0].start(rgb);
  if (present_[1]) decoders_[1].start(nir);
}

std::uint64_t Rgb14Coder::overrun() const {
  return (present_[0] ? decoders_[0].overrun() : 0) + (present_[1] ? decoders_[1].overrun() : 0);
}

void Rgb14Coder::decode(std::uint32_t context, std::uint8_t* out) {
  Context& owner = follow(context);
  Context& models = *contexts_[current_];
  if (present_[0]) {
    std::uint16_t rgb[3];
    decode_rgb(decoders_[0], models.rgb, owner.last, rgb);
    std::memcpy(owner.last, rgb, sizeof rgb);
  }
  if (present_[1]) {
    ArithmeticDecoder& d = decoders_[1];
    const std::uint32_t used = d.decode_symbol(models.nir_used);
    std::uint32_t low = owner.last[3] & 0xFFu, high = owner.last[3] >> 8;
    if (used & 1) low = fold8(static_cast<std::int32_t>(d.decode_symbol(models.nir_diff[0]) + low));
    if (used & 2) high = fold8(static_cast<std::int32_t>(d.decode_symbol(models.nir_diff[1]) + high));
    owner.last[3] = static_cast<std::uint16_t>(low | (high << 8));
  }
  store_u16s(out, owner.last, nir_ ? 4 : 3);
}

void Rgb14Coder::encode(std::uint32_t context, const std::uint8_t* in) {
  Context& owner = follow(context);
  Context& models = *contexts_[current_];
  std::uint16_t value[4] = {};
  load_u16s(in, value, nir_ ? 4 : 3);
  changed_[0] |= std::memcmp(value, owner.last, 6) != 0;
  encode_rgb(encoders_[0], models.rgb, owner.last, value);
  std::memcpy(owner.last, value, 6);
  if (!nir_) return;
  changed_[1] |= value[3] != owner.last[3];
  const std::uint32_t low_changed = (value[3] & 0xFFu) != (owner.last[3] & 0xFFu);
  const std::uint32_t high_changed = (value[3] >> 8) != (owner.last[3] >> 8);
  ArithmeticEncoder& e = encoders_[1];
  e.encode_symbol(models.nir_used, low_changed | (high_changed << 1));
  if (low_changed) e.encode_symbol(models.nir_diff[0], fold8((value[3] & 0xFF) - (owner.last[3] & 0xFF)));
  if (high_changed) e.encode_symbol(models.nir_diff[1], fold8((value[3] >> 8) - (owner.last[3] >> 8)));
  owner.last[3] = value[3];
}

std::array<std::vector<std::uint8_t>, 2> Rgb14Coder::finish() {
  std::array<std::vector<std::uint8_t>, 2> layers;
  for (int i = 0; i < 2; ++i) {
    if (!changed_[i]) continue;
    encoders_[i].finish();
    layers[i] = std::move(encoders_[i].bytes());
  }
  return layers;
}

struct WavePacket14Coder::Context {
  explicit Context(bool decoding) : coder(decoding) {}
  void start(const std::uint8_t* seed) {
    coder.reset();
    std::memcpy(last, seed, sizeof last);
    used = true;
  }
  void start_from(const Context& other) { start(other.last); }
  bool used = false;
  std::uint8_t last[kWavePacketBytes] = {};
  WavePacketCoder coder;
};

WavePacket14Coder::WavePacket14Coder(bool decoding, bool version4) : decoding_(decoding), version4_(version4) {}
WavePacket14Coder::~WavePacket14Coder() = default;

void WavePacket14Coder::start(const std::uint8_t* first, std::uint32_t context) {
  for (auto& c : contexts_)
    if (c) c->used = false;
  current_ = context;
  if (!contexts_[current_]) contexts_[current_] = std::make_unique<Context>(decoding_);
  contexts_[current_]->start(first);
  std::memcpy(previous_, first, sizeof previous_);
  encoder_.clear();
  changed_ = false;
}

WavePacket14Coder::Context& WavePacket14Coder::follow(std::uint32_t context) {
  return follow_channel(contexts_, current_, context, version4_, [&] { return std::make_unique<Context>(decoding_); });
}

void WavePacket14Coder::set_layer(std::span<const std::uint8_t> layer) {
  present_ = !layer.empty();
  if (present_) decoder_.start(layer);
}

std::uint64_t WavePacket14Coder::overrun() const { return present_ ? decoder_.overrun() : 0; }

void WavePacket14Coder::decode(std::uint32_t context, std::uint8_t* out) {
  Context& owner = follow(context);
  if (present_) {
    contexts_[current_]->coder.decode(decoder_, owner.last, owner.last);
    std::memcpy(previous_, owner.last, sizeof previous_);
  }
  std::memcpy(out, previous_, sizeof previous_);
}

void WavePacket14Coder::encode(std::uint32_t context, const std::uint8_t* in) {
  Context& owner = follow(context);
  changed_ |= std::memcmp(in, owner.last, sizeof owner.last) != 0;
  contexts_[current_]->coder.encode(encoder_, owner.last, in);
  std::memcpy(owner.last, in, sizeof owner.last);
}

std::vector<std::uint8_t> WavePacket14Coder::finish() {
  if (!changed_) return {};
  encoder_.finish();
  return std::move(encoder_.bytes());
}

struct Byte14Coder::Context {
  Context(std::size_t count, bool decoding) : last(count), models(count) {
    for (auto& m : models) m.create(256, decoding);
  }
  void start(const std::uint8_t* seed) {
    for (auto& m : models) m.reset();
    std::memcpy(last.data(), seed, last.size());
    used = true;
  }
  void start_from(const Context& other) { start(other.last.data()); }
  bool used = false;
  std::vector<std::uint8_t> last;
  std::vector<SymbolModel> models;
};

Byte14Coder::Byte14Coder(std::size_t count, bool decoding, bool version4)
    : count_(count), decoding_(decoding), version4_(version4), decoders_(count), present_(count),
      encoders_(decoding ? 0 : count), changed_(count) {}
Byte14Coder::~Byte14Coder() = default;

void Byte14Coder::start(const std::uint8_t* first, std::uint32_t context) {
  for (auto& c : contexts_)
    if (c) c->used = false;
  current_ = context;
  if (!contexts_[current_]) contexts_[current_] = std::make_unique<Context>(count_, decoding_);
  contexts_[current_]->start(first);
  for (auto& e : encoders_) e.clear();
  std::fill(changed_.begin(), changed_.end(), 0);
}

Byte14Coder::Context& Byte14Coder::follow(std::uint32_t context) {
  return follow_channel(contexts_, current_, context, version4_,
                        [&] { return std::make_unique<Context>(count_, decoding_); });
}

void Byte14Coder::set_layers(std::span<const std::span<const std::uint8_t>> layers) {
  for (std::size_t i = 0; i < count_; ++i) {
    present_[i] = !layers[i].empty();
    if (present_[i]) decoders_[i].start(layers[i]);
  }
}

std::uint64_t Byte14Coder::overrun() const {
  std::uint64_t n = 0;
  for (std::size_t i = 0; i < count_; ++i)
    if (present_[i]) n += decoders_[i].overrun();
  return n;
}

void Byte14Coder::decode(std::uint32_t context, std::uint8_t* out) {
  Context& owner = follow(context);
  Context& models = *contexts_[current_];
  for (std::size_t i = 0; i < count_; ++i)
    if (present_[i]) owner.last[i] = static_cast<std::uint8_t>(owner.last[i] + decoders_[i].decode_symbol(models.models[i]));
  std::memcpy(out, owner.last.data(), count_);
}

void Byte14Coder::encode(std::uint32_t context, const std::uint8_t* in) {
  Context& owner = follow(context);
  Context& models = *contexts_[current_];
  for (std::size_t i = 0; i < count_; ++i) {
    changed_[i] |= in[i] != owner.last[i];
    encoders_[i].encode_symbol(models.models[i], static_cast<std::uint8_t>(in[i] - owner.last[i]));
    owner.last[i] = in[i];
  }
}

std::vector<std::vector<std::uint8_t>> Byte14Coder::finish() {
  std::vector<std::vector<std::uint8_t>> layers(count_);
  for (std::size_t i = 0; i < count_; ++i) {
    if (!changed_[i]) continue;
    encoders_[i].finish();
    layers[i] = std::move(encoders_[i].bytes());
  }
  return layers;
}

}  // namespace vola::io::laz
