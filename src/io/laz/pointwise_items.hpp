// The point-wise item coders (compressors 1 and 2): every part of a record is coded
// into one arithmetic stream, point after point. POINT10 v2 (the 20 bytes common to LAS
// formats 0-5), GPSTIME11 v2, RGB12 v2, WAVEPACKET13 v1 and BYTE v2 (extra bytes). Each coder keeps the
// last record's values and its models; start() resets both from a chunk's first record
// (which the chunk stores raw). Internal to the LAZ codec (src/io/laz).
#pragma once

#include <cstdint>
#include <cstring>
#include <vector>

#include "item_common.hpp"
#include "wave_packet_coder.hpp"
#include "vola/little_endian.hpp"

namespace vola::io::laz {

// LAS formats 0-5's first 20 bytes: X, Y, Z (int32), intensity (uint16), the returns
// byte (return number 3 bits, number of returns 3 bits, scan direction, edge of flight
// line), classification, scan angle rank (int8), user data, point source id (uint16).
class Point10Coder {
 public:
  explicit Point10Coder(bool decoding)
      : bit_byte_(256, decoding), classification_(256, decoding), user_data_(256, decoding) {
    changed_.create(64, decoding);
    for (auto& m : scan_angle_) m.create(256, decoding);
    intensity_ic_.create(16, 4, decoding);
    source_ic_.create(16, 1, decoding);
    dx_.create(32, 2, decoding);
    dy_.create(32, 22, decoding);
    dz_.create(32, 20, decoding);
  }

  void start(const std::uint8_t* first) {
    changed_.reset();
    for (auto& m : scan_angle_) m.reset();
    bit_byte_.forget();
    classification_.forget();
    user_data_.forget();
    for (auto* ic : {&intensity_ic_, &source_ic_, &dx_, &dy_, &dz_}) ic->reset();
    for (int i = 0; i < 16; ++i) x_median_[i] = y_median_[i] = Median5{};
    std::memset(last_intensity_, 0, sizeof last_intensity_);
    std::memset(last_height_, 0, sizeof last_height_);
    std::memcpy(last_, first, 20);
    last_[12] = last_[13] = 0;  // the intensity history starts at 0, not at the first point's
  }

  [[gnu::always_inline]] void decode(ArithmeticDecoder& d, std::uint8_t* out) {
    const std::uint32_t changed = d.decode_symbol(changed_);
    std::uint32_t m, n;
    if (changed) {
      if (changed & 32) last_[14] = static_cast<std::uint8_t>(d.decode_symbol(bit_byte_.at(last_[14])));
      n = (last_[14] >> 3) & 7;
      const std::uint32_t r = last_[14] & 7;
      m = kReturnMap8[n][r];
      std::uint16_t intensity = last_intensity_[m];
      if (changed & 16) {
        intensity = static_cast<std::uint16_t>(intensity_ic_.decode(d, intensity, m < 3 ? m : 3));
        last_intensity_[m] = intensity;
      }
      std::memcpy(last_ + 12, &intensity, 2);
      if (changed & 8) last_[15] = static_cast<std::uint8_t>(d.decode_symbol(classification_.at(last_[15])));
      if (changed & 4)
        last_[16] = static_cast<std::uint8_t>(last_[16] + d.decode_symbol(scan_angle_[(last_[14] >> 6) & 1]));
      if (changed & 2) last_[17] = static_cast<std::uint8_t>(d.decode_symbol(user_data_.at(last_[17])));
      if (changed & 1) {
        const auto source = static_cast<std::uint16_t>(source_ic_.decode(d, load_le<std::uint16_t>(last_ + 18)));
        std::memcpy(last_ + 18, &source, 2);
      }
      decode_xyz(d, m, n, return_level(n, r));
    } else {
      n = (last_[14] >> 3) & 7;
      const std::uint32_t r = last_[14] & 7;
      decode_xyz(d, kReturnMap8[n][r], n, return_level(n, r));
    }
    std::memcpy(out, last_, 20);
  }

  void encode(ArithmeticEncoder& e, const std::uint8_t* in) {
    const std::uint32_t r = in[14] & 7, n = (in[14] >> 3) & 7;
    const std::uint32_t m = kReturnMap8[n][r], l = return_level(n, r);
    const auto intensity = load_le<std::uint16_t>(in + 12);
    const std::uint32_t changed = (std::uint32_t{last_[14] != in[14]} << 5) |
                                  (std::uint32_t{last_intensity_[m] != intensity} << 4) |
                                  (std::uint32_t{last_[15] != in[15]} << 3) | (std::uint32_t{last_[16] != in[16]} << 2) |
                                  (std::uint32_t{last_[17] != in[17]} << 1) |
                                  std::uint32_t{std::memcmp(last_ + 18, in + 18, 2) != 0};
    e.encode_symbol(changed_, changed);
    if (changed & 32) e.encode_symbol(bit_byte_.at(last_[14]), in[14]);
    if (changed & 16) {
      intensity_ic_.encode(e, last_intensity_[m], intensity, m < 3 ? m : 3);
      last_intensity_[m] = intensity;
    }
    if (changed & 8) e.encode_symbol(classification_.at(last_[15]), in[15]);
    if (changed & 4) e.encode_symbol(scan_angle_[(in[14] >> 6) & 1], static_cast<std::uint8_t>(in[16] - last_[16]));
    if (changed & 2) e.encode_symbol(user_data_.at(last_[17]), in[17]);
    if (changed & 1) source_ic_.encode(e, load_le<std::uint16_t>(last_ + 18), load_le<std::uint16_t>(in + 18));
    const std::int32_t dx = diff(in, 0), dy = diff(in, 4);
    dx_.encode(e, x_median_[m].get(), dx, n == 1);
    x_median_[m].add(dx);
    const std::uint32_t kx = dx_.k();
    dy_.encode(e, y_median_[m].get(), dy, (n == 1) + (kx < 20 ? even(kx) : 20));
    y_median_[m].add(dy);
    const std::uint32_t kz = (dx_.k() + dy_.k()) / 2;
    const auto z = load_le<std::int32_t>(in + 8);
    dz_.encode(e, last_height_[l], z, (n == 1) + (kz < 18 ? even(kz) : 18));
    last_height_[l] = z;
    std::memcpy(last_, in, 20);
  }

 private:
  [[gnu::always_inline]] void decode_xyz(ArithmeticDecoder& d, std::uint32_t m, std::uint32_t n, std::uint32_t l) {
    const std::int32_t dx = dx_.decode(d, x_median_[m].get(), n == 1);
    add(0, dx);
    x_median_[m].add(dx);
    const std::uint32_t kx = dx_.k();
    const std::int32_t dy = dy_.decode(d, y_median_[m].get(), (n == 1) + (kx < 20 ? even(kx) : 20));
    add(4, dy);
    y_median_[m].add(dy);
    const std::uint32_t kz = (dx_.k() + dy_.k()) / 2;
    const std::int32_t z = dz_.decode(d, last_height_[l], (n == 1) + (kz < 18 ? even(kz) : 18));
    std::memcpy(last_ + 8, &z, 4);
    last_height_[l] = z;
  }
  void add(int at, std::int32_t delta) {
    const std::uint32_t v = load_le<std::uint32_t>(last_ + at) + static_cast<std::uint32_t>(delta);
    std::memcpy(last_ + at, &v, 4);
  }
  std::int32_t diff(const std::uint8_t* in, int at) const {
    return static_cast<std::int32_t>(load_le<std::uint32_t>(in + at) - load_le<std::uint32_t>(last_ + at));
  }

  SymbolModel changed_, scan_angle_[2];
  LazyModels<256> bit_byte_, classification_, user_data_;
  IntegerCoder intensity_ic_, source_ic_, dx_, dy_, dz_;
  Median5 x_median_[16], y_median_[16];
  std::uint16_t last_intensity_[16];
  std::int32_t last_height_[8];
  std::uint8_t last_[20];
};

class GpsTime11Coder {
 public:
  explicit GpsTime11Coder(bool decoding) : gps_(false, decoding) {}
  void start(const std::uint8_t* first) { gps_.start(load_le<std::uint64_t>(first)); }
  [[gnu::always_inline]] void decode(ArithmeticDecoder& d, std::uint8_t* out) {
    const std::uint64_t t = gps_.decode(d);
    std::memcpy(out, &t, 8);
  }
  void encode(ArithmeticEncoder& e, const std::uint8_t* in) { gps_.encode(e, load_le<std::uint64_t>(in)); }

 private:
  GpsTimeCoder gps_;
};

class Rgb12Coder {
 public:
  explicit Rgb12Coder(bool decoding) { models_.create(decoding); }
  void start(const std::uint8_t* first) {
    models_.reset();
    load_u16s(first, last_, 3);
  }
  [[gnu::always_inline]] void decode(ArithmeticDecoder& d, std::uint8_t* out) {
    std::uint16_t rgb[3];
    decode_rgb(d, models_, last_, rgb);
    std::memcpy(last_, rgb, sizeof rgb);
    store_u16s(out, rgb, 3);
  }
  void encode(ArithmeticEncoder& e, const std::uint8_t* in) {
    std::uint16_t rgb[3];
    load_u16s(in, rgb, 3);
    encode_rgb(e, models_, last_, rgb);
    std::memcpy(last_, rgb, sizeof rgb);
  }

 private:
  RgbModels models_;
  std::uint16_t last_[3] = {};
};

// WAVEPACKET13 (version 1, the only one LASzip defines).
class WavePacket13Coder {
 public:
  explicit WavePacket13Coder(bool decoding) : coder_(decoding) {}
  void start(const std::uint8_t* first) {
    coder_.reset();
    std::memcpy(last_, first, kWavePacketBytes);
  }
  [[gnu::always_inline]] void decode(ArithmeticDecoder& d, std::uint8_t* out) {
    coder_.decode(d, last_, last_);
    std::memcpy(out, last_, kWavePacketBytes);
  }
  void encode(ArithmeticEncoder& e, const std::uint8_t* in) {
    coder_.encode(e, last_, in);
    std::memcpy(last_, in, kWavePacketBytes);
  }

 private:
  WavePacketCoder coder_;
  std::uint8_t last_[kWavePacketBytes] = {};
};

// Extra bytes: each byte as its difference to the same byte of the last record, one
// model per byte position.
class ByteCoder {
 public:
  ByteCoder(std::size_t count, bool decoding) : models_(count), last_(count) {
    for (auto& m : models_) m.create(256, decoding);
  }
  void start(const std::uint8_t* first) {
    for (auto& m : models_) m.reset();
    std::memcpy(last_.data(), first, last_.size());
  }
  [[gnu::always_inline]] void decode(ArithmeticDecoder& d, std::uint8_t* out) {
    for (std::size_t i = 0; i < last_.size(); ++i)
      last_[i] = static_cast<std::uint8_t>(last_[i] + d.decode_symbol(models_[i]));
    std::memcpy(out, last_.data(), last_.size());
  }
  void encode(ArithmeticEncoder& e, const std::uint8_t* in) {
    for (std::size_t i = 0; i < last_.size(); ++i) {
      e.encode_symbol(models_[i], static_cast<std::uint8_t>(in[i] - last_[i]));
      last_[i] = in[i];
    }
  }

 private:
  std::vector<SymbolModel> models_;
  std::vector<std::uint8_t> last_;
};

}  // namespace vola::io::laz
