// The encoding halves of the GPS time sequences and the RGB prediction (the decoding
// halves are inline in the header).
#include "item_common.hpp"

#include <algorithm>
#include <cmath>

namespace vola::io::laz {
namespace {

// The difference of two times' bit patterns when it fits 32 bits.
bool small_difference(std::uint64_t time, std::uint64_t base, std::int32_t& diff) {
  const auto d = static_cast<std::int64_t>(time - base);
  diff = static_cast<std::int32_t>(d);
  return d == diff;
}

}  // namespace

void GpsTimeCoder::encode_full(ArithmeticEncoder& e, std::uint64_t time) {
  ic_.encode(e, static_cast<std::int32_t>(times_[last_] >> 32), static_cast<std::int32_t>(time >> 32), 8);
  e.write_int(static_cast<std::uint32_t>(time));
  next_ = (next_ + 1) & 3;
  last_ = next_;
  diffs_[last_] = 0;
  extremes_[last_] = 0;
  times_[last_] = time;
}

void GpsTimeCoder::encode_with_step(ArithmeticEncoder& e, std::int32_t diff) {
  const std::int32_t step = diffs_[last_];
  // The multiple of the regular step; only which band it falls in matters to the
  // decoder, so the rounding need not match any other writer's.
  const double ratio = std::clamp(static_cast<double>(diff) / static_cast<double>(step), -1e6, 1e6);
  const auto multi = static_cast<std::int32_t>(std::lround(ratio));
  if (multi == 1) {
    e.encode_symbol(multi_, 1);
    ic_.encode(e, step, diff, 1);
    extremes_[last_] = 0;
  } else if (multi > 0 && multi < kMulti) {
    e.encode_symbol(multi_, static_cast<std::uint32_t>(multi));
    ic_.encode(e, wrapping_times(multi, step), diff, multi < 10 ? 2 : 3);
  } else if (multi >= kMulti) {
    e.encode_symbol(multi_, kMulti);
    ic_.encode(e, wrapping_times(kMulti, step), diff, 4);
    count_extreme(diff);
  } else if (multi < 0 && multi > kMultiMinus) {
    e.encode_symbol(multi_, static_cast<std::uint32_t>(kMulti - multi));
    ic_.encode(e, wrapping_times(multi, step), diff, 5);
  } else if (multi < 0) {
    e.encode_symbol(multi_, static_cast<std::uint32_t>(kMulti - kMultiMinus));
    ic_.encode(e, wrapping_times(kMultiMinus, step), diff, 6);
    count_extreme(diff);
  } else {
    e.encode_symbol(multi_, 0);
    ic_.encode(e, 0, diff, 7);
    count_extreme(diff);
  }
}

void GpsTimeCoder::encode(ArithmeticEncoder& e, std::uint64_t time) {
  const std::uint32_t shift = layered_ ? 1 : 0;
  for (int jumps = 0; jumps < 2; ++jumps) {
    const bool zero_step = diffs_[last_] == 0;
    if (!layered_ && time == times_[last_]) {
      e.encode_symbol(zero_step ? zero_diff_ : multi_, zero_step ? 0 : kUnchanged);
      return;
    }
    std::int32_t diff = 0;
    if (small_difference(time, times_[last_], diff)) {
      if (zero_step) {
        e.encode_symbol(zero_diff_, 1 - shift);
        ic_.encode(e, 0, diff, 0);
        diffs_[last_] = diff;
        extremes_[last_] = 0;
      } else {
        encode_with_step(e, diff);
      }
      times_[last_] = time;
      return;
    }
    // Maybe the time continues another sequence (only on the first try: the jump lands
    // where the difference is small).
    std::uint32_t other = 1;
    while (other < 4 && !small_difference(time, times_[(last_ + other) & 3], diff)) ++other;
    if (other == 4 || jumps > 0) break;
    e.encode_symbol(zero_step ? zero_diff_ : multi_, zero_step ? other + 2 - shift : kCodeFull + other - shift);
    last_ = (last_ + other) & 3;
  }
  e.encode_symbol(diffs_[last_] == 0 ? zero_diff_ : multi_, (diffs_[last_] == 0 ? 2 : kCodeFull) - shift);
  encode_full(e, time);
}

void encode_rgb(ArithmeticEncoder& e, RgbModels& m, const std::uint16_t last[3], const std::uint16_t in[3]) {
  auto low = [](std::uint32_t v) { return static_cast<std::int32_t>(v & 0xFF); };
  auto high = [](std::uint32_t v) { return static_cast<std::int32_t>(v >> 8); };
  std::uint32_t used = 0;
  for (int c = 0; c < 3; ++c) {
    used |= std::uint32_t{low(last[c]) != low(in[c])} << (2 * c);
    used |= std::uint32_t{high(last[c]) != high(in[c])} << (2 * c + 1);
  }
  const bool colour = in[0] != in[1] || in[0] != in[2];
  used |= std::uint32_t{colour} << 6;
  e.encode_symbol(m.used, used);
  std::int32_t diff_low = 0, diff_high = 0;
  if (used & 1) {
    diff_low = low(in[0]) - low(last[0]);
    e.encode_symbol(m.diff[0], fold8(diff_low));
  }
  if (used & 2) {
    diff_high = high(in[0]) - high(last[0]);
    e.encode_symbol(m.diff[1], fold8(diff_high));
  }
  if (!colour) return;
  if (used & 4) e.encode_symbol(m.diff[2], fold8(low(in[1]) - clamp8(diff_low + low(last[1]))));
  if (used & 16) {
    diff_low = (diff_low + low(in[1]) - low(last[1])) / 2;
    e.encode_symbol(m.diff[4], fold8(low(in[2]) - clamp8(diff_low + low(last[2]))));
  }
  if (used & 8) e.encode_symbol(m.diff[3], fold8(high(in[1]) - clamp8(diff_high + high(last[1]))));
  if (used & 32) {
    diff_high = (diff_high + high(in[1]) - high(last[1])) / 2;
    e.encode_symbol(m.diff[5], fold8(high(in[2]) - clamp8(diff_high + high(last[2]))));
  }
}

}  // namespace vola::io::laz
