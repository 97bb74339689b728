// Version 1 of the point-wise item coders: what LASzip 1.x (2011) wrote, before version
// 2 gave the coordinates return-aware contexts. POINT10 v1, GPSTIME11 v1, RGB12 v1 and
// BYTE v1, written from the LAZ format's description of each item. Files of that age
// are still served (old county and state archives), so the reader takes them; vola
// writes version 2 (the encoders below are what the tests round-trip through).
// Internal to the LAZ codec (src/io/laz).
#pragma once

#include <cstdint>
#include <cstring>
#include <vector>

#include "integer_coder.hpp"
#include "item_common.hpp"
#include "vola/little_endian.hpp"

namespace vola::io::laz {

// The 20 bytes of LAS formats 0-5. X and Y are predicted by the median of the last
// three differences, Z by the last Z; the magnitude class (k) of the X correction picks
// Y's context and the mean of both Z's. A 6-bit mask then says which of intensity (32),
// the returns byte (16), classification (8), scan angle (4), user data (2) and point
// source (1) changed; each changed field is coded against its last value.
class Point10V1Coder {
 public:
  explicit Point10V1Coder(bool decoding)
      : bit_byte_(256, decoding), classification_(256, decoding), user_data_(256, decoding) {
    changed_.create(64, decoding);
    dx_.create(32, 1, decoding);
    dy_.create(32, 20, decoding);
    dz_.create(32, 20, decoding);
    intensity_.create(16, 1, decoding);
    scan_angle_.create(8, 2, decoding);
    source_.create(16, 1, decoding);
  }

  void start(const std::uint8_t* first) {
    changed_.reset();
    bit_byte_.forget();
    classification_.forget();
    user_data_.forget();
    for (auto* ic : {&dx_, &dy_, &dz_, &intensity_, &scan_angle_, &source_}) ic->reset();
    for (int i = 0; i < 3; ++i) x_diffs_[i] = y_diffs_[i] = 0;
    next_ = 0;
    std::memcpy(last_, first, 20);
  }

  void decode(ArithmeticDecoder& d, std::uint8_t* out) {
    const std::int32_t dx = dx_.decode(d, median3(x_diffs_));
    add(0, dx);
    std::uint32_t k = dx_.k();
    const std::int32_t dy = dy_.decode(d, median3(y_diffs_), k < 19 ? k : 19);
    add(4, dy);
    k = (k + dy_.k()) / 2;
    store(8, dz_.decode(d, load_le<std::int32_t>(last_ + 8), k < 19 ? k : 19));
    if (const std::uint32_t changed = d.decode_symbol(changed_)) {
      if (changed & 32) store16(12, intensity_.decode(d, load_le<std::uint16_t>(last_ + 12)));
      if (changed & 16) last_[14] = static_cast<std::uint8_t>(d.decode_symbol(bit_byte_.at(last_[14])));
      if (changed & 8) last_[15] = static_cast<std::uint8_t>(d.decode_symbol(classification_.at(last_[15])));
      if (changed & 4) last_[16] = static_cast<std::uint8_t>(scan_angle_.decode(d, last_[16], k < 3 ? 1 : 0));
      if (changed & 2) last_[17] = static_cast<std::uint8_t>(d.decode_symbol(user_data_.at(last_[17])));
      if (changed & 1) store16(18, source_.decode(d, load_le<std::uint16_t>(last_ + 18)));
    }
    remember(dx, dy);
    std::memcpy(out, last_, 20);
  }

  void encode(ArithmeticEncoder& e, const std::uint8_t* in) {
    const std::int32_t dx = diff(in, 0), dy = diff(in, 4);
    dx_.encode(e, median3(x_diffs_), dx);
    std::uint32_t k = dx_.k();
    dy_.encode(e, median3(y_diffs_), dy, k < 19 ? k : 19);
    k = (k + dy_.k()) / 2;
    dz_.encode(e, load_le<std::int32_t>(last_ + 8), load_le<std::int32_t>(in + 8), k < 19 ? k : 19);
    const std::uint32_t changed =
        (std::uint32_t{std::memcmp(last_ + 12, in + 12, 2) != 0} << 5) | (std::uint32_t{last_[14] != in[14]} << 4) |
        (std::uint32_t{last_[15] != in[15]} << 3) | (std::uint32_t{last_[16] != in[16]} << 2) |
        (std::uint32_t{last_[17] != in[17]} << 1) | std::uint32_t{std::memcmp(last_ + 18, in + 18, 2) != 0};
    e.encode_symbol(changed_, changed);
    if (changed & 32) intensity_.encode(e, load_le<std::uint16_t>(last_ + 12), load_le<std::uint16_t>(in + 12));
    if (changed & 16) e.encode_symbol(bit_byte_.at(last_[14]), in[14]);
    if (changed & 8) e.encode_symbol(classification_.at(last_[15]), in[15]);
    if (changed & 4) scan_angle_.encode(e, last_[16], in[16], k < 3 ? 1 : 0);
    if (changed & 2) e.encode_symbol(user_data_.at(last_[17]), in[17]);
    if (changed & 1) source_.encode(e, load_le<std::uint16_t>(last_ + 18), load_le<std::uint16_t>(in + 18));
    remember(dx, dy);
    std::memcpy(last_, in, 20);
  }

 private:
  static std::int32_t median3(const std::int32_t v[3]) {
    const std::int32_t lo = v[0] < v[1] ? v[0] : v[1], hi = v[0] < v[1] ? v[1] : v[0];
    return v[2] < lo ? lo : (v[2] > hi ? hi : v[2]);
  }
  void remember(std::int32_t dx, std::int32_t dy) {
    x_diffs_[next_] = dx;
    y_diffs_[next_] = dy;
    next_ = next_ == 2 ? 0 : next_ + 1;
  }
  void add(int at, std::int32_t delta) {
    store(at, static_cast<std::int32_t>(load_le<std::uint32_t>(last_ + at) + static_cast<std::uint32_t>(delta)));
  }
  void store(int at, std::int32_t v) { std::memcpy(last_ + at, &v, 4); }
  void store16(int at, std::int32_t v) {
    const auto u = static_cast<std::uint16_t>(v);
    std::memcpy(last_ + at, &u, 2);
  }
  std::int32_t diff(const std::uint8_t* in, int at) const {
    return static_cast<std::int32_t>(load_le<std::uint32_t>(in + at) - load_le<std::uint32_t>(last_ + at));
  }

  SymbolModel changed_;
  LazyModels<256> bit_byte_, classification_, user_data_;
  IntegerCoder dx_, dy_, dz_, intensity_, scan_angle_, source_;
  std::int32_t x_diffs_[3] = {}, y_diffs_[3] = {};
  int next_ = 0;
  std::uint8_t last_[20] = {};
};

// GPS time as one sequence: the difference of the doubles' bit patterns to the last
// time, predicted as a multiple of the last regular difference (the multiplier coded
// first, 0..509), or the whole 64 bits. While the last difference is 0 a 3-symbol
// model says unchanged / a 32-bit difference / a full time.
class GpsTime11V1Coder {
 public:
  static constexpr std::uint32_t kMultiMax = 512;

  explicit GpsTime11V1Coder(bool decoding) {
    multi_.create(kMultiMax, decoding);
    zero_diff_.create(3, decoding);
    ic_.create(32, 6, decoding);
  }
  void start(const std::uint8_t* first) {
    multi_.reset();
    zero_diff_.reset();
    ic_.reset();
    last_ = load_le<std::uint64_t>(first);
    last_diff_ = 0;
    extremes_ = 0;
  }

  void decode(ArithmeticDecoder& d, std::uint8_t* out) {
    if (last_diff_ == 0) {
      const std::uint32_t code = d.decode_symbol(zero_diff_);
      if (code == 1) {
        last_diff_ = ic_.decode(d, 0, 0);
        last_ = wrapping_plus(last_, last_diff_);
      } else if (code == 2) {
        last_ = read_int64(d);
      }
    } else {
      const std::uint32_t multi = d.decode_symbol(multi_);
      if (multi < kMultiMax - 2) {
        last_ = wrapping_plus(last_, step(multi, [&](std::int32_t prediction, std::uint32_t context) {
                                return ic_.decode(d, prediction, context);
                              }));
      } else if (multi == kMultiMax - 2) {
        last_ = read_int64(d);
      }  // kMultiMax - 1: unchanged
    }
    std::memcpy(out, &last_, 8);
  }

  void encode(ArithmeticEncoder& e, const std::uint8_t* in) {
    const auto time = load_le<std::uint64_t>(in);
    const auto diff64 = static_cast<std::int64_t>(time - last_);
    const auto diff = static_cast<std::int32_t>(diff64);
    const bool fits = diff64 == diff;
    if (last_diff_ == 0) {
      if (time == last_) {
        e.encode_symbol(zero_diff_, 0);
      } else if (fits) {
        e.encode_symbol(zero_diff_, 1);
        ic_.encode(e, 0, diff, 0);
        last_diff_ = diff;
      } else {
        e.encode_symbol(zero_diff_, 2);
        write_int64(e, time);
      }
    } else if (time == last_) {
      e.encode_symbol(multi_, kMultiMax - 1);
    } else if (fits) {
      // The nearest multiple of the regular difference, within the multiplier's range.
      const double ratio = static_cast<double>(diff) / static_cast<double>(last_diff_) + 0.5;
      const std::uint32_t multi =
          ratio < 1 ? 0 : (ratio >= kMultiMax - 3 ? kMultiMax - 3 : static_cast<std::uint32_t>(ratio));
      e.encode_symbol(multi_, multi);
      step(multi, [&](std::int32_t prediction, std::uint32_t context) {
        ic_.encode(e, prediction, diff, context);
        return diff;
      });
    } else {
      e.encode_symbol(multi_, kMultiMax - 2);
      write_int64(e, time);
    }
    last_ = time;
  }

 private:
  // The prediction and context of multiplier `multi`, the coded difference from `code`
  // (which decodes or encodes it), and the bookkeeping of the regular difference: a
  // multiplier of 1 makes the difference regular, four extreme ones in a row do too.
  template <class Code>
  std::int32_t step(std::uint32_t multi, Code code) {
    std::int32_t diff;
    if (multi == 1) {
      diff = code(last_diff_, 1);
      last_diff_ = diff;
      extremes_ = 0;
    } else if (multi == 0) {
      diff = code(last_diff_ / 4, 2);
      count_extreme(diff);
    } else {
      const std::int32_t prediction = wrapping_times(static_cast<std::int32_t>(multi), last_diff_);
      diff = code(prediction, multi < 10 ? 3 : (multi < 50 ? 4 : 5));
      if (multi == kMultiMax - 3) count_extreme(diff);
    }
    return diff;
  }
  void count_extreme(std::int32_t diff) {
    if (++extremes_ > 3) {
      last_diff_ = diff;
      extremes_ = 0;
    }
  }
  static std::uint64_t read_int64(ArithmeticDecoder& d) {
    const std::uint64_t low = d.read_int();
    return (std::uint64_t{d.read_int()} << 32) | low;
  }
  static void write_int64(ArithmeticEncoder& e, std::uint64_t v) {
    e.write_int(static_cast<std::uint32_t>(v));
    e.write_int(static_cast<std::uint32_t>(v >> 32));
  }

  SymbolModel multi_, zero_diff_;
  IntegerCoder ic_;
  std::uint64_t last_ = 0;
  std::int32_t last_diff_ = 0;
  int extremes_ = 0;
};

// RGB: a 6-bit mask of the bytes (low and high of red, green, blue) that changed, then
// each changed byte against its last value, one context per byte.
class Rgb12V1Coder {
 public:
  explicit Rgb12V1Coder(bool decoding) {
    used_.create(64, decoding);
    ic_.create(8, 6, decoding);
  }
  void start(const std::uint8_t* first) {
    used_.reset();
    ic_.reset();
    std::memcpy(last_, first, 6);
  }
  void decode(ArithmeticDecoder& d, std::uint8_t* out) {
    const std::uint32_t used = d.decode_symbol(used_);
    for (std::uint32_t b = 0; b < 6; ++b)
      if (used & (1u << b)) last_[b] = static_cast<std::uint8_t>(ic_.decode(d, last_[b], b));
    std::memcpy(out, last_, 6);
  }
  void encode(ArithmeticEncoder& e, const std::uint8_t* in) {
    std::uint32_t used = 0;
    for (std::uint32_t b = 0; b < 6; ++b) used |= std::uint32_t{in[b] != last_[b]} << b;
    e.encode_symbol(used_, used);
    for (std::uint32_t b = 0; b < 6; ++b)
      if (used & (1u << b)) ic_.encode(e, last_[b], in[b], b);
    std::memcpy(last_, in, 6);
  }

 private:
  SymbolModel used_;
  IntegerCoder ic_;
  std::uint8_t last_[6] = {};
};

// Extra bytes: each byte against the same byte of the last record, one context per
// byte position.
class ByteV1Coder {
 public:
  ByteV1Coder(std::size_t count, bool decoding) : last_(count) {
    ic_.create(8, static_cast<std::uint32_t>(count), decoding);
  }
  void start(const std::uint8_t* first) {
    ic_.reset();
    std::memcpy(last_.data(), first, last_.size());
  }
  void decode(ArithmeticDecoder& d, std::uint8_t* out) {
    for (std::uint32_t i = 0; i < last_.size(); ++i) last_[i] = static_cast<std::uint8_t>(ic_.decode(d, last_[i], i));
    std::memcpy(out, last_.data(), last_.size());
  }
  void encode(ArithmeticEncoder& e, const std::uint8_t* in) {
    for (std::uint32_t i = 0; i < last_.size(); ++i) {
      ic_.encode(e, last_[i], in[i], i);
      last_[i] = in[i];
    }
  }

 private:
  IntegerCoder ic_;
  std::vector<std::uint8_t> last_;
};

}  // namespace vola::io::laz
