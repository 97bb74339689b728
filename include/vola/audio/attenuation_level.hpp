// The attenuation bin of an amplitude, llround(-20 * log10(a) / width) clamped to a range,
// without a logarithm per call: thresholding asks it of every reflecting voxel.
//
// The bin boundaries are precomputed as amplitudes (edge L = 10^(-(L + 0.5) * width / 20));
// a first guess from the double's exponent and a 2048-entry table of log2 is then corrected
// by comparing the amplitude with the edges. An amplitude within a relative 1e-9 of an
// edge takes the exact formula instead: the formula's own rounding error (a few ulp of
// log10 and two products, under 1e-11 levels) is far below the 1e-9 margin (at least
// 1.4e-9 levels for width <= 6 dB), so the bin is always the one the formula gives.
#pragma once

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <vector>

namespace vola::audio {

class AttenuationLevels {
 public:
  // Levels -offset .. count - 1 - offset; results are clamped to that range.
  AttenuationLevels(double bin_width_db, std::int64_t offset, std::int64_t count);

  // The clamped index level + offset in [0, count), as exact_index() gives it.
  std::int64_t index(double amplitude) const noexcept;
  // The formula itself, for amplitudes near an edge and for tests.
  std::int64_t exact_index(double amplitude) const noexcept;

 private:
  double inverse_width_;
  double levels_per_log2_;  // -20 * log10(2) / width
  std::int64_t offset_, count_;
  // Edge i (the lowest amplitude of index i; 0 for the last) times 1 - margin and 1 + margin:
  // amplitudes between the two are too near the edge to decide by comparison.
  std::vector<double> edge_below_, edge_above_;
  std::array<double, 2048> mantissa_log2_{};  // log2(1.m) at the middle of each top-11-bit interval
};

// ---- implementation (inline: called once per reflecting voxel) ----

inline std::int64_t AttenuationLevels::index(double amplitude) const noexcept {
  if (edge_below_.empty() || !(amplitude > 0.0) || !std::isfinite(amplitude)) return exact_index(amplitude);
  const auto bits = std::bit_cast<std::uint64_t>(amplitude);
  const auto exponent = static_cast<int>((bits >> 52) & 0x7ff);
  if (exponent == 0) return exact_index(amplitude);  // subnormal
  const double log2_guess = (exponent - 1023) + mantissa_log2_[(bits >> 41) & 0x7ff];
  double guess = std::nearbyint(log2_guess * levels_per_log2_) + static_cast<double>(offset_);
  guess = std::clamp(guess, 0.0, static_cast<double>(count_ - 1));
  auto i = static_cast<std::int64_t>(guess);
  // Index i holds the amplitudes above edge i, up to edge i - 1; the guess is off by at most
  // a level, so the loop mostly returns at once.
  for (int steps = 0; steps < 8; ++steps) {
    const auto u = static_cast<std::size_t>(i);
    if (amplitude <= edge_above_[u]) {
      if (amplitude >= edge_below_[u]) return exact_index(amplitude);
      ++i;  // weaker than this level: i < count - 1 since the last edge is 0
      continue;
    }
    if (i > 0 && amplitude >= edge_below_[u - 1]) {
      if (amplitude <= edge_above_[u - 1]) return exact_index(amplitude);
      --i;
      continue;
    }
    return i;
  }
  return exact_index(amplitude);
}

}  // namespace vola::audio
