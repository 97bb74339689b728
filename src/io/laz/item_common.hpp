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
void decode_rgb(ArithmeticDecoder& d, RgbModels& m, const std::uint16_t last[3], std::uint16_t out[3]);
void encode_rgb(ArithmeticEncoder& e, RgbModels& m, const std::uint16_t last[3], const std::uint16_t in[3]);

inline void load_u16s(const std::uint8_t* p, std::uint16_t* out, int n) { std::memcpy(out, p, 2 * std::size_t(n)); }
inline void store_u16s(std::uint8_t* p, const std::uint16_t* in, int n) { std::memcpy(p, in, 2 * std::size_t(n)); }

}  // namespace vola::io::laz
