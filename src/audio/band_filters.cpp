#include "vola/audio/band_filters.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "vola/audio/convolve.hpp"

namespace vola::audio {

std::array<std::vector<double>, kOctaveBands.size()> octave_filters(double sample_rate) {
  // A design grid of about 3 Hz and taps spanning about 1/30 s: the 125 Hz band's edge at
  // 177 Hz needs its transition (a quarter octave either side, 28 Hz below) resolved.
  std::size_t n = 2048;
  while (static_cast<double>(n) < sample_rate / 3.0 && n < (std::size_t{1} << 22)) n *= 2;
  const auto taps = std::clamp<std::size_t>(static_cast<std::size_t>(sample_rate / 30.0), 64, n);
  constexpr std::size_t kBands = kOctaveBands.size();
  std::array<std::vector<double>, kBands - 1> low;
  for (std::size_t b = 0; b + 1 < kBands; ++b) {
    const double edge = kOctaveBands[b] * std::numbers::sqrt2;
    std::vector<double> magnitude(n / 2 + 1);
    for (std::size_t k = 0; k < magnitude.size(); ++k) {
      const double f = static_cast<double>(k) * sample_rate / static_cast<double>(n);
      // 1 up to a quarter octave below the edge, 0 from a quarter octave above, a raised
      // cosine over log frequency between: neighbouring bands overlap little.
      const double x = f > 0.0 ? 2.0 * std::log2(f / edge) : -1.0;
      magnitude[k] = x <= -0.5 ? 1.0 : x >= 0.5 ? 0.0 : 0.5 * (1.0 + std::cos(std::numbers::pi * (x + 0.5)));
    }
    low[b] = minimum_phase_fir(magnitude, taps);
  }
  std::array<std::vector<double>, kBands> bank;
  for (std::size_t b = 0; b < kBands; ++b) {
    bank[b].assign(taps, 0.0);
    if (b + 1 < kBands) {
      bank[b] = low[b];
    } else {
      bank[b][0] = 1.0;
    }
    if (b > 0)
      for (std::size_t i = 0; i < taps; ++i) bank[b][i] -= low[b - 1][i];
  }
  return bank;
}

}  // namespace vola::audio
