// Pieces shared by the point-wise (LAS 1.0-1.3 records) and layered (LAS 1.4 records)
// item coders: the return-number context tables, the GPS time sequences and the RGB
// prediction. Internal to the LAZ codec (src/io/laz).
#pragma once

#include <cstdint>
#include <cstring>

#include "integer_coder.hpp"

namespace vola::io::laz {

// Point-wise records: [number of returns][return number] (3 bits each) -> one of 16
// coordinate-difference histories. Sound pairs (1 <= r <= n) get their own entries;
// the rest share entries, as some writers number returns from 0 or overflow n.
inline constexpr std::uint8_t kReturnMap8[8][8] = {
    {15, 14, 13, 12, 11, 10, 9, 8}, {14, 0, 1, 3, 6, 10, 10, 9},   {13, 1, 2, 4, 7, 11, 11, 10},
    {12, 3, 4, 5, 8, 12, 12, 11},   {11, 6, 7, 8, 9, 13, 13, 12},  {10, 10, 11, 12, 13, 14, 14, 13},
    {9, 10, 11, 12, 13, 14, 15, 14}, {8, 9, 10, 11, 12, 13, 14, 15}};

// Layered records: [n][r] (4 bits each) -> 6 coordinate contexts: single returns, the
// first/last of two, and first, middle and last returns of longer pulses.
inline constexpr std::uint8_t kReturnMap16[16][16] = {
    {0, 1, 2, 3, 4, 5, 3, 4, 4, 5, 5, 5, 5, 5, 5, 5}, {1, 0, 1, 3, 3, 3, 3, 3, 3, 3, 3, 3, 3, 3, 3, 3},
    {2, 1, 2, 4, 4, 4, 4, 4, 4, 4, 4, 3, 3, 3, 3, 3}, {3, 3, 4, 5, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4},
    {4, 3, 4, 4, 5, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4}, {5, 3, 4, 4, 4, 5, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4},
    {3, 3, 4, 4, 4, 4, 5, 4, 4, 4, 4, 4, 4, 4, 4, 4}, {4, 3, 4, 4, 4, 4, 4, 5, 4, 4, 4, 4, 4, 4, 4, 4},
    {4, 3, 4, 4, 4, 4, 4, 4, 5, 4, 4, 4, 4, 4, 4, 4}, {5, 3, 4, 4, 4, 4, 4, 4, 4, 5, 4, 4, 4, 4, 4, 4},
    {5, 3, 4, 4, 4, 4, 4, 4, 4, 4, 5, 4, 4, 4, 4, 4}, {5, 3, 3, 4, 4, 4, 4, 4, 4, 4, 4, 5, 5, 4, 4, 4},
    {5, 3, 3, 4, 4, 4, 4, 4, 4, 4, 4, 5, 5, 5, 4, 4}, {5, 3, 3, 4, 4, 4, 4, 4, 4, 4, 4, 4, 5, 5, 5, 4},
    {5, 3, 3, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4, 5, 5, 5}, {5, 3, 3, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4, 5, 5}};

// The height context: how far the return is from the last one (|n - r|, at most 7 for
// layered records; point-wise records have n, r < 8 so the cap never bites).
inline std::uint32_t return_level(std::uint32_t n, std::uint32_t r) {
  const std::uint32_t d = n > r ? n - r : r - n;
  return d < 7 ? d : 7;
}

// Bits 1.. of k (the coordinate coders' context drops bit 0).
inline std::uint32_t even(std::uint32_t k) { return k & ~1u; }

inline std::uint8_t fold8(std::int32_t v) { return static_cast<std::uint8_t>(v); }
inline std::int32_t clamp8(std::int32_t v) { return v < 0 ? 0 : (v > 255 ? 255 : v); }

// GPS times as up to 4 interleaved sequences (several scanners or flight lines write
// alternating times). Each sequence remembers its last time and its last regular step
// as an integer difference of the doubles' bit patterns; a time is coded as a multiple
// of that step plus a correction, as a jump to another sequence, or in full. Point-wise
// (GPSTIME11 v2) and layered (POINT14 v3) records code this alike, except that layered
// records never code "unchanged" (a flag in the point says so) and so number the
// codes from "unchanged" on one lower (and their multiplier model has one symbol less).
class GpsTimeCoder {
 public:
  static constexpr std::int32_t kMulti = 500, kMultiMinus = -10;
  static constexpr std::uint32_t kUnchanged = kMulti - kMultiMinus + 1;  // 511
  static constexpr std::uint32_t kCodeFull = kUnchanged + 1;            // 512
  static constexpr std::uint32_t kTotal = kUnchanged + 5;               // 516

  GpsTimeCoder() = default;
  GpsTimeCoder(bool layered, bool decoding) { create(layered, decoding); }
  void create(bool layered, bool decoding) {
    layered_ = layered;
    multi_.create(layered ? kTotal - 1 : kTotal, decoding);
    zero_diff_.create(layered ? 5 : 6, decoding);
    ic_.create(32, 9, decoding);
  }
  void start(std::uint64_t first) {
    multi_.reset();
    zero_diff_.reset();
    ic_.reset();
    last_ = next_ = 0;
    for (int i = 0; i < 4; ++i) times_[i] = diffs_[i] = extremes_[i] = 0;
    times_[0] = first;
  }
  std::uint64_t current() const { return times_[last_]; }

  std::uint64_t decode(ArithmeticDecoder& d);
  void encode(ArithmeticEncoder& e, std::uint64_t time);

 private:
  void decode_with_step(ArithmeticDecoder& d, std::uint32_t multi);
  void decode_full(ArithmeticDecoder& d);
  void encode_with_step(ArithmeticEncoder& e, std::int32_t diff);
  void encode_full(ArithmeticEncoder& e, std::uint64_t time);
  void count_extreme(std::int32_t diff);

  bool layered_ = false;
  SymbolModel multi_, zero_diff_;
  IntegerCoder ic_;
  std::uint32_t last_ = 0, next_ = 0;
  std::uint64_t times_[4] = {};
  std::int32_t diffs_[4] = {};
  std::int32_t extremes_[4] = {};
};

// RGB as the byte-wise difference to the last colour; green and blue are predicted from
// red's (and green's) change, and one flag says "all three equal" (grey).
struct RgbModels {
  SymbolModel used, diff[6];
  void create(bool decoding) {
    used.create(128, decoding);
    for (auto& m : diff) m.create(256, decoding);
  }
  void reset() {
    used.reset();
    for (auto& m : diff) m.reset();
  }
};
void encode_rgb(ArithmeticEncoder& e, RgbModels& m, const std::uint16_t last[3], const std::uint16_t in[3]);

// The decoders are inlined into the per-point loops, like the arithmetic decoder's
// calls (see ArithmeticDecoder).

// Products of steps wrap like the format's 32-bit arithmetic.
inline std::int32_t wrapping_times(std::int32_t a, std::int32_t b) {
  return static_cast<std::int32_t>(static_cast<std::uint32_t>(a) * static_cast<std::uint32_t>(b));
}
inline std::uint64_t wrapping_plus(std::uint64_t time, std::int32_t diff) {
  return time + static_cast<std::uint64_t>(static_cast<std::int64_t>(diff));
}

inline void GpsTimeCoder::count_extreme(std::int32_t diff) {
  // Four extreme steps in a row become the sequence's new regular step.
  if (++extremes_[last_] > 3) {
    diffs_[last_] = diff;
    extremes_[last_] = 0;
  }
}

[[gnu::always_inline]] inline void GpsTimeCoder::decode_full(ArithmeticDecoder& d) {
  next_ = (next_ + 1) & 3;
  const auto high = static_cast<std::uint32_t>(ic_.decode(d, static_cast<std::int32_t>(times_[last_] >> 32), 8));
  times_[next_] = (std::uint64_t{high} << 32) | d.read_int();
  last_ = next_;
  diffs_[last_] = 0;
  extremes_[last_] = 0;
}

// A multiple of the sequence's step: the multiplier picks the prediction and the
// context, and the end bands (0, kMulti and up, kMultiMinus and down) count as extreme
// steps. One call of the integer decoder for all bands keeps the inlined code small.
[[gnu::always_inline]] inline void GpsTimeCoder::decode_with_step(ArithmeticDecoder& d, std::uint32_t multi) {
  const auto signed_multi = static_cast<std::int32_t>(multi);
  std::int32_t factor = signed_multi;
  std::uint32_t context;
  bool extreme = false;
  if (multi == 0) {
    context = 7;
    extreme = true;
  } else if (multi < static_cast<std::uint32_t>(kMulti)) {
    context = multi == 1 ? 1 : multi < 10 ? 2 : 3;
  } else if (multi == static_cast<std::uint32_t>(kMulti)) {
    context = 4;
    extreme = true;
  } else if (kMulti - signed_multi > kMultiMinus) {
    factor = kMulti - signed_multi;
    context = 5;
  } else {
    factor = kMultiMinus;
    context = 6;
    extreme = true;
  }
  const std::int32_t diff = ic_.decode(d, wrapping_times(factor, diffs_[last_]), context);
  times_[last_] = wrapping_plus(times_[last_], diff);
  if (multi == 1) extremes_[last_] = 0;  // the regular step again
  else if (extreme) count_extreme(diff);
}

[[gnu::always_inline]] inline std::uint64_t GpsTimeCoder::decode(ArithmeticDecoder& d) {
  // A jump to another sequence is followed by a code in that sequence; a sound stream
  // jumps at most once per point, so the bound only stops corrupt input.
  for (int jumps = 0; jumps < 4; ++jumps) {
    if (diffs_[last_] == 0) {
      const std::uint32_t code = d.decode_symbol(zero_diff_) + (layered_ ? 1 : 0);
      if (code == 0) return times_[last_];
      if (code == 1) {
        diffs_[last_] = ic_.decode(d, 0, 0);
        times_[last_] = wrapping_plus(times_[last_], diffs_[last_]);
        extremes_[last_] = 0;
        return times_[last_];
      }
      if (code == 2) {
        decode_full(d);
        return times_[last_];
      }
      last_ = (last_ + code - 2) & 3;
      continue;
    }
    std::uint32_t multi = d.decode_symbol(multi_);
    if (layered_ && multi >= kUnchanged) ++multi;  // to the point-wise numbering
    if (multi < kCodeFull) {
      if (!layered_ && multi == kUnchanged) return times_[last_];
      decode_with_step(d, multi);
      return times_[last_];
    }
    if (multi == kCodeFull) {
      decode_full(d);
      return times_[last_];
    }
    last_ = (last_ + multi - kCodeFull) & 3;
  }
  return times_[last_];
}

[[gnu::always_inline]] inline void decode_rgb(ArithmeticDecoder& d, RgbModels& m, const std::uint16_t last[3], std::uint16_t out[3]) {
  const std::uint32_t used = d.decode_symbol(m.used);
  auto low = [](std::uint32_t v) { return static_cast<std::int32_t>(v & 0xFF); };
  auto high = [](std::uint32_t v) { return static_cast<std::int32_t>(v >> 8); };
  std::uint32_t r = (used & 1) ? fold8(static_cast<std::int32_t>(d.decode_symbol(m.diff[0])) + low(last[0])) : low(last[0]);
  r |= std::uint32_t{(used & 2) ? fold8(static_cast<std::int32_t>(d.decode_symbol(m.diff[1])) + high(last[0]))
                                 : static_cast<std::uint8_t>(high(last[0]))} << 8;
  out[0] = static_cast<std::uint16_t>(r);
  if (!(used & 64)) {  // grey: green and blue equal red
    out[1] = out[2] = out[0];
    return;
  }
  std::int32_t diff = low(r) - low(last[0]);
  std::uint32_t g = (used & 4) ? fold8(static_cast<std::int32_t>(d.decode_symbol(m.diff[2])) + clamp8(diff + low(last[1])))
                               : low(last[1]);
  std::uint32_t b = 0;
  if (used & 16) {
    diff = (diff + (low(g) - low(last[1]))) / 2;
    b = fold8(static_cast<std::int32_t>(d.decode_symbol(m.diff[4])) + clamp8(diff + low(last[2])));
  } else {
    b = low(last[2]);
  }
  diff = high(r) - high(last[0]);
  std::uint32_t gh = (used & 8) ? fold8(static_cast<std::int32_t>(d.decode_symbol(m.diff[3])) + clamp8(diff + high(last[1])))
                                : high(last[1]);
  g |= gh << 8;
  if (used & 32) {
    diff = (diff + (high(g) - high(last[1]))) / 2;
    b |= std::uint32_t{fold8(static_cast<std::int32_t>(d.decode_symbol(m.diff[5])) + clamp8(diff + high(last[2])))} << 8;
  } else {
    b |= last[2] & 0xFF00u;
  }
  out[1] = static_cast<std::uint16_t>(g);
  out[2] = static_cast<std::uint16_t>(b);
}

inline void load_u16s(const std::uint8_t* p, std::uint16_t* out, int n) { std::memcpy(out, p, 2 * std::size_t(n)); }
inline void store_u16s(std::uint8_t* p, const std::uint16_t* in, int n) { std::memcpy(p, in, 2 * std::size_t(n)); }

}  // namespace vola::io::laz
