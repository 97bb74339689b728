// POINT14 (versions 3 and 4): the layered coder of LAS formats 6-10's first 30 bytes.
//
// The XY layer carries, per point, a 7-bit mask of what changed against the last point
// of the same scanner channel (channel, point source, GPS time, scan angle, number of
// returns, and how the return number moved), then X and Y. The other layers code Z,
// classification, flags, intensity, scan angle, user data, point source and GPS time,
// each with contexts taken from the XY layer's returns and "time changed" bits.
#include <cstring>

#include "layered_items.hpp"
#include "vola/little_endian.hpp"

namespace vola::io::laz {

struct Point14Context {
  explicit Point14Context(bool decoding)
      : return_count(16, decoding),
        return_number(16, decoding),
        classification(256, decoding),
        flags(64, decoding),
        user_data(256, decoding),
        gps(true, decoding) {
    for (auto& m : changed) m.create(128, decoding);
    channel.create(3, decoding);
    return_gps_same.create(13, decoding);
    dx.create(32, 2, decoding);
    dy.create(32, 22, decoding);
    dz.create(32, 20, decoding);
    intensity.create(16, 4, decoding);
    scan_angle.create(16, 2, decoding);
    source.create(16, 1, decoding);
  }

  // Fresh models, histories seeded from `seed` (the point before this context's first).
  void start(const Point14& seed) {
    for (auto& m : changed) m.reset();
    channel.reset();
    return_gps_same.reset();
    return_count.forget();
    return_number.forget();
    classification.forget();
    flags.forget();
    user_data.forget();
    for (auto* ic : {&dx, &dy, &dz, &intensity, &scan_angle, &source}) ic->reset();
    for (int i = 0; i < 12; ++i) x_median[i] = y_median[i] = Median5{};
    for (auto& z : last_z) z = seed.z;
    for (auto& i : last_intensity) i = seed.intensity;
    gps.start(seed.gps);
    last = seed;
    last.gps_changed = false;
    used = true;
  }

  bool used = false;
  Point14 last;
  SymbolModel changed[8], channel, return_gps_same;
  LazyModels<16> return_count, return_number;
  LazyModels<64> classification, flags, user_data;
  IntegerCoder dx, dy, dz, intensity, scan_angle, source;
  Median5 x_median[12], y_median[12];
  std::int32_t last_z[8];
  std::uint16_t last_intensity[8];
  GpsTimeCoder gps;
};

Point14 unpack_point14(const std::uint8_t* p) {
  Point14 q;
  q.x = load_le<std::int32_t>(p);
  q.y = load_le<std::int32_t>(p + 4);
  q.z = load_le<std::int32_t>(p + 8);
  q.intensity = load_le<std::uint16_t>(p + 12);
  q.return_number = p[14] & 15;
  q.return_count = p[14] >> 4;
  q.class_flags = p[15] & 15;
  q.channel = (p[15] >> 4) & 3;
  q.scan_direction = (p[15] >> 6) & 1;
  q.edge = p[15] >> 7;
  q.classification = p[16];
  q.user_data = p[17];
  q.scan_angle = load_le<std::int16_t>(p + 18);
  q.source = load_le<std::uint16_t>(p + 20);
  q.gps = load_le<std::uint64_t>(p + 22);
  return q;
}

void pack_point14(const Point14& q, std::uint8_t* p) {
  std::memcpy(p, &q.x, 4);
  std::memcpy(p + 4, &q.y, 4);
  std::memcpy(p + 8, &q.z, 4);
  std::memcpy(p + 12, &q.intensity, 2);
  p[14] = static_cast<std::uint8_t>(q.return_number | (q.return_count << 4));
  p[15] = static_cast<std::uint8_t>(q.class_flags | (q.channel << 4) | (q.scan_direction << 6) | (q.edge << 7));
  p[16] = q.classification;
  p[17] = q.user_data;
  std::memcpy(p + 18, &q.scan_angle, 2);
  std::memcpy(p + 20, &q.source, 2);
  std::memcpy(p + 22, &q.gps, 8);
}

namespace {

// Context of the last point's return: first (1), last (2), and whether its time changed (4).
std::uint32_t last_return_context(const Point14& last) {
  return (last.return_number == 1 ? 1u : 0u) + (last.return_number >= last.return_count ? 2u : 0u) +
         (last.gps_changed ? 4u : 0u);
}
// Context of this point's return: single (3), first (2), last (1), middle (0).
std::uint32_t return_class(std::uint32_t n, std::uint32_t r) { return (r == 1 ? 2u : 0u) + (r >= n ? 1u : 0u); }
std::uint32_t flag_bits(const Point14& p) {
  return (std::uint32_t{p.edge} << 5) | (std::uint32_t{p.scan_direction} << 4) | p.class_flags;
}

}  // namespace

Point14Coder::Point14Coder(bool decoding, bool version4) : decoding_(decoding), version4_(version4) {}
Point14Coder::~Point14Coder() = default;

Point14Context& Point14Coder::context_for(std::uint32_t channel, const Point14& seed) {
  auto& c = contexts_[channel];
  if (!c) c = std::make_unique<Point14Context>(decoding_);
  if (!c->used) c->start(seed);
  return *c;
}

std::uint32_t Point14Coder::start(const std::uint8_t* first) {
  for (auto& c : contexts_)
    if (c) c->used = false;
  const Point14 seed = unpack_point14(first);
  current_ = seed.channel;
  context_for(current_, seed);
  changed_.fill(false);
  for (auto& e : encoders_) e.clear();
  return current_;
}

void Point14Coder::set_layers(const std::array<std::span<const std::uint8_t>, kLayers14>& layers, bool xyz_only) {
  for (int i = 0; i < kLayers14; ++i) {
    // XY is decoded even when empty: a chunk of more than one point must have it.
    present_[i] = i == kXy || (!layers[i].empty() && (!xyz_only || i == kZ));
    if (present_[i]) decoders_[i].start(layers[i]);
  }
}

std::uint64_t Point14Coder::overrun() const {
  std::uint64_t n = 0;
  for (int i = 0; i < kLayers14; ++i)
    if (present_[i]) n += decoders_[i].overrun();
  return n;
}

void Point14Coder::decode_returns(Point14Context& c, std::uint32_t changed, std::uint32_t& n,
                                           std::uint32_t& r) {
  ArithmeticDecoder& d = decoders_[kXy];
  const std::uint32_t last_n = c.last.return_count, last_r = c.last.return_number;
  n = (changed & 4) ? d.decode_symbol(c.return_count.at(last_n)) : last_n;
  switch (changed & 3) {
    case 0: r = last_r; break;
    case 1: r = (last_r + 1) & 15; break;
    case 2: r = (last_r + 15) & 15; break;
    default:
      r = (changed & 16) ? d.decode_symbol(c.return_number.at(last_r))
                         : (last_r + d.decode_symbol(c.return_gps_same) + 2) & 15;
  }
  c.last.return_count = static_cast<std::uint8_t>(n);
  c.last.return_number = static_cast<std::uint8_t>(r);
}

void Point14Coder::decode_fields(Point14Context& c, Point14& last, std::uint32_t changed, std::uint32_t n,
                                 std::uint32_t r) {
  const std::uint32_t gps_change = (changed >> 4) & 1;
  const std::uint32_t cpr = return_class(n, r);
  if (present_[kZ]) {
    const std::uint32_t kz = (c.dx.k() + c.dy.k()) / 2;
    const std::uint32_t l = return_level(n, r);
    last.z = c.dz.decode(decoders_[kZ], c.last_z[l], (n == 1) + (kz < 18 ? even(kz) : 18));
    c.last_z[l] = last.z;
  }
  if (present_[kClass]) {
    const std::uint32_t key = ((last.classification & 0x1Fu) << 1) + (cpr == 3 ? 1u : 0u);
    last.classification = static_cast<std::uint8_t>(decoders_[kClass].decode_symbol(c.classification.at(key)));
  }
  if (present_[kFlags]) {
    const std::uint32_t f = decoders_[kFlags].decode_symbol(c.flags.at(flag_bits(last)));
    last.edge = (f >> 5) & 1;
    last.scan_direction = (f >> 4) & 1;
    last.class_flags = f & 15;
  }
  if (present_[kIntensity]) {
    std::uint16_t& history = c.last_intensity[(cpr << 1) | gps_change];
    history = static_cast<std::uint16_t>(c.intensity.decode(decoders_[kIntensity], history, cpr));
    last.intensity = history;
  }
  if (present_[kScanAngle] && (changed & 8))
    last.scan_angle = static_cast<std::int16_t>(c.scan_angle.decode(decoders_[kScanAngle], last.scan_angle, gps_change));
  if (present_[kUserData])
    last.user_data = static_cast<std::uint8_t>(decoders_[kUserData].decode_symbol(c.user_data.at(last.user_data / 4u)));
  if (present_[kSource] && (changed & 32))
    last.source = static_cast<std::uint16_t>(c.source.decode(decoders_[kSource], last.source));
  if (present_[kGps] && gps_change) last.gps = c.gps.decode(decoders_[kGps]);
}

std::uint32_t Point14Coder::decode(std::uint8_t* out) {
  ArithmeticDecoder& d = decoders_[kXy];
  Point14Context* c = contexts_[current_].get();
  const std::uint32_t changed = d.decode_symbol(c->changed[last_return_context(c->last)]);
  const bool switched = changed & 64;
  if (switched) {
    const std::uint32_t channel = (current_ + d.decode_symbol(c->channel) + 1) & 3;
    c = &context_for(channel, c->last);
    current_ = channel;
    c->last.channel = static_cast<std::uint8_t>(channel);
  }
  std::uint32_t n, r;
  decode_returns(*c, changed, n, r);
  Point14& last = c->last;
  const std::uint32_t gps_change = (changed >> 4) & 1;
  const std::uint32_t history = (std::uint32_t{kReturnMap16[n][r]} << 1) | gps_change;
  const std::int32_t dx = c->dx.decode(d, c->x_median[history].get(), n == 1);
  last.x = static_cast<std::int32_t>(static_cast<std::uint32_t>(last.x) + static_cast<std::uint32_t>(dx));
  c->x_median[history].add(dx);
  const std::uint32_t kx = c->dx.k();
  const std::int32_t dy = c->dy.decode(d, c->y_median[history].get(), (n == 1) + (kx < 20 ? even(kx) : 20));
  last.y = static_cast<std::int32_t>(static_cast<std::uint32_t>(last.y) + static_cast<std::uint32_t>(dy));
  c->y_median[history].add(dy);
  decode_fields(*c, last, changed, n, r);
  pack_point14(last, out);
  last.gps_changed = gps_change != 0;
  return version4_ || switched ? current_ : 0;
}

void Point14Coder::encode_returns(Point14Context& c, const Point14& last, const Point14& p, std::uint32_t changed) {
  ArithmeticEncoder& e = encoders_[kXy];
  if (changed & 4) e.encode_symbol(c.return_count.at(last.return_count), p.return_count);
  if ((changed & 3) != 3) return;
  if (changed & 16) {
    e.encode_symbol(c.return_number.at(last.return_number), p.return_number);
  } else {
    const int diff = int{p.return_number} - int{last.return_number};
    e.encode_symbol(c.return_gps_same, static_cast<std::uint32_t>(diff > 1 ? diff - 2 : diff + 16 - 2));
  }
}

void Point14Coder::encode_fields(Point14Context& c, const Point14& last, const Point14& p, std::uint32_t changed) {
  const std::uint32_t n = p.return_count, r = p.return_number;
  const std::uint32_t gps_change = (changed >> 4) & 1;
  const std::uint32_t cpr = return_class(n, r);
  const std::uint32_t kz = (c.dx.k() + c.dy.k()) / 2;
  const std::uint32_t l = return_level(n, r);
  c.dz.encode(encoders_[kZ], c.last_z[l], p.z, (n == 1) + (kz < 18 ? even(kz) : 18));
  c.last_z[l] = p.z;
  changed_[kZ] = true;  // always written, as LASzip does
  changed_[kClass] |= p.classification != last.classification;
  const std::uint32_t key = ((last.classification & 0x1Fu) << 1) + (cpr == 3 ? 1u : 0u);
  encoders_[kClass].encode_symbol(c.classification.at(key), p.classification);
  changed_[kFlags] |= flag_bits(p) != flag_bits(last);
  encoders_[kFlags].encode_symbol(c.flags.at(flag_bits(last)), flag_bits(p));
  changed_[kIntensity] |= p.intensity != last.intensity;
  std::uint16_t& history = c.last_intensity[(cpr << 1) | gps_change];
  c.intensity.encode(encoders_[kIntensity], history, p.intensity, cpr);
  history = p.intensity;
  if (changed & 8) {
    changed_[kScanAngle] = true;
    c.scan_angle.encode(encoders_[kScanAngle], last.scan_angle, p.scan_angle, gps_change);
  }
  changed_[kUserData] |= p.user_data != last.user_data;
  encoders_[kUserData].encode_symbol(c.user_data.at(last.user_data / 4u), p.user_data);
  if (changed & 32) {
    changed_[kSource] = true;
    c.source.encode(encoders_[kSource], last.source, p.source);
  }
  if (gps_change) {
    changed_[kGps] = true;
    c.gps.encode(encoders_[kGps], p.gps);
  }
}

std::uint32_t Point14Coder::encode(const std::uint8_t* in) {
  const Point14 p = unpack_point14(in);
  Point14Context* c = contexts_[current_].get();
  const std::uint32_t lpr = last_return_context(c->last);
  // Against the last point of p's channel when that channel was seen before.
  const bool switched = p.channel != current_;
  const Point14& last = switched && contexts_[p.channel] && contexts_[p.channel]->used ? contexts_[p.channel]->last : c->last;
  const std::uint32_t last_r = last.return_number;
  std::uint32_t changed = (std::uint32_t{switched} << 6) | (std::uint32_t{p.source != last.source} << 5) |
                          (std::uint32_t{p.gps != last.gps} << 4) | (std::uint32_t{p.scan_angle != last.scan_angle} << 3) |
                          (std::uint32_t{p.return_count != last.return_count} << 2);
  if (p.return_number != last_r) {
    if (p.return_number == ((last_r + 1) & 15)) changed |= 1;
    else if (p.return_number == ((last_r + 15) & 15)) changed |= 2;
    else changed |= 3;
  }
  ArithmeticEncoder& e = encoders_[kXy];
  e.encode_symbol(c->changed[lpr], changed);
  if (switched) {
    e.encode_symbol(c->channel, ((p.channel - current_ + 4) & 3) - 1);
    c = &context_for(p.channel, c->last);
    current_ = p.channel;
  }
  const Point14 before = c->last;  // `last` may alias it
  encode_returns(*c, before, p, changed);
  const std::uint32_t n = p.return_count, r = p.return_number;
  const std::uint32_t gps_change = (changed >> 4) & 1;
  const std::uint32_t history = (std::uint32_t{kReturnMap16[n][r]} << 1) | gps_change;
  const auto dx = static_cast<std::int32_t>(static_cast<std::uint32_t>(p.x) - static_cast<std::uint32_t>(before.x));
  c->dx.encode(e, c->x_median[history].get(), dx, n == 1);
  c->x_median[history].add(dx);
  const std::uint32_t kx = c->dx.k();
  const auto dy = static_cast<std::int32_t>(static_cast<std::uint32_t>(p.y) - static_cast<std::uint32_t>(before.y));
  c->dy.encode(e, c->y_median[history].get(), dy, (n == 1) + (kx < 20 ? even(kx) : 20));
  c->y_median[history].add(dy);
  encode_fields(*c, before, p, changed);
  c->last = p;
  c->last.gps_changed = gps_change != 0;
  return version4_ || switched ? current_ : 0;
}

std::array<std::vector<std::uint8_t>, kLayers14> Point14Coder::finish() {
  std::array<std::vector<std::uint8_t>, kLayers14> layers;
  changed_[kXy] = true;
  for (int i = 0; i < kLayers14; ++i) {
    if (!changed_[i]) continue;
    encoders_[i].finish();
    layers[i] = std::move(encoders_[i].bytes());
  }
  return layers;
}

}  // namespace vola::io::laz
