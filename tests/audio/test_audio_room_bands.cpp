// Frequency in the physical response: air absorption against ISO 9613-1's table; per
// octave band, a closed room's reverberation time (Schroeder's T30 of the band's energy:
// direct sound, image sources and traced tail) against Eyring's formula with the band's
// absorption and the air's, T = 24 ln(10) V / (c (-S ln(1 - alpha) + 4 m V)); the rendering
// through the octave bank causal and, for equal bands, the broadband response.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>

#include "audio_test_support.hpp"
#include "vola/audio/air.hpp"
#include "vola/audio/convolve.hpp"
#include "vola/audio/room_response.hpp"

namespace {

using namespace vola;
using namespace vola::audio;
using vola_audio_test::Shoebox;
using vola_audio_test::shoebox_tree;
using vola_audio_test::t30;

TEST(AudioAir, AttenuationMatchesTheIsoTable) {
  // ISO 9613-1:1993 table 1, 20 degrees C, 50% relative humidity, 101.325 kPa (dB/km).
  const double table[6] = {0.44, 1.31, 2.73, 4.66, 9.86, 29.4};
  for (std::size_t b = 0; b < 6; ++b)
    EXPECT_NEAR(1000.0 * air_attenuation_db_per_m(kOctaveBands[b], 20.0, 50.0) / table[b], 1.0, 0.015) << kOctaveBands[b];
  // Drier air absorbs the highs more: 4 kHz at 20 degrees C, 10% (ISO: 109 dB/km).
  EXPECT_GT(air_attenuation_db_per_m(4000.0, 20.0, 10.0), 2.0 * air_attenuation_db_per_m(4000.0, 20.0, 50.0));
}

// A windowed-sinc band-pass from fc / sqrt(2) to fc * sqrt(2) (Blackman window), linear
// phase: an analysis filter independent of the renderer's minimum-phase bank.
std::vector<double> octave_band_pass(double fc, double rate, std::size_t taps) {
  const double f1 = fc / std::numbers::sqrt2 / rate, f2 = std::min(fc * std::numbers::sqrt2 / rate, 0.5);
  std::vector<double> h(taps);
  const double mid = 0.5 * static_cast<double>(taps - 1);
  for (std::size_t i = 0; i < taps; ++i) {
    const double n = static_cast<double>(i) - mid;
    auto sinc = [](double x) { return x == 0.0 ? 1.0 : std::sin(std::numbers::pi * x) / (std::numbers::pi * x); };
    const double phase = 2.0 * std::numbers::pi * static_cast<double>(i) / static_cast<double>(taps - 1);
    const double w = 0.42 - 0.5 * std::cos(phase) + 0.08 * std::cos(2.0 * phase);
    h[i] = (2.0 * f2 * sinc(2.0 * f2 * n) - 2.0 * f1 * sinc(2.0 * f1 * n)) * w;
  }
  return h;
}

TEST(AudioRoomBands, PerBandT30FollowsEyringWithTheBandsAbsorptionAndTheAir) {
  const double rate = 16000.0, c = 343.0, voxel = 0.1;
  const double size[3] = {5.0, 4.4, 3.6};
  const double absorption[6] = {0.05, 0.1, 0.15, 0.2, 0.3, 0.4};
  Shoebox box{};
  for (int a = 0; a < 3; ++a) {
    box.lo[a] = 3;
    box.hi[a] = 4 + static_cast<std::uint32_t>(std::lround(size[a] / voxel));
  }
  const Tree tree = shoebox_tree(box, voxel);
  MaterialTable table;
  table.fallback.bands.clear();
  for (const double a : absorption) table.fallback.bands.push_back(std::sqrt(1.0 - a));
  const AcousticScene scene(tree, table);
  const Room room(scene);
  ASSERT_TRUE(room.per_band());
  RoomOptions o;
  o.sample_rate = rate;
  o.speed_of_sound = c;
  o.rays = 8000;
  o.threads = 2;
  o.air = true;
  const double volume = size[0] * size[1] * size[2];
  const double surface = 2.0 * (size[0] * size[1] + size[1] * size[2] + size[2] * size[0]);
  auto eyring = [&](std::size_t b) {
    const double m = air_attenuation_db_per_m(kOctaveBands[b], o.celsius, o.humidity) / (10.0 * std::log10(std::numbers::e));
    return 24.0 * std::log(10.0) * volume / (c * (surface * -std::log(1.0 - absorption[b]) + 4.0 * m * volume));
  };
  o.max_length = 1.5 * eyring(0);
  const Point s{0.4 + 0.31 * size[0], 0.4 + 0.37 * size[1], 0.4 + 0.45 * size[2]};
  const Point l{0.4 + 0.72 * size[0], 0.4 + 0.61 * size[1], 0.4 + 0.52 * size[2]};
  const RoomResponse r = room_response(room, s, l, o);
  for (std::size_t b = 0; b < 6; ++b) {
    // The band's energy per millisecond: direct sound, image sources and tail.
    std::vector<double> energy(r.late.bands.size() + 1, 0.0);
    const double bin = static_cast<double>(r.late.bin_samples);
    auto at = [&](double sample) { return std::min(energy.size() - 1, static_cast<std::size_t>(sample / bin)); };
    energy[at(r.direct_sample)] += r.direct_bands[b] * r.direct_bands[b];
    for (const ImageSource& is : r.early.images) energy[at(is.delay * rate)] += is.bands[b] * is.bands[b];
    for (std::size_t i = 0; i < r.late.bands.size(); ++i) energy[i] += r.late.bands[i][b];
    std::vector<double> amplitude(energy.size());
    for (std::size_t i = 0; i < energy.size(); ++i) amplitude[i] = std::sqrt(energy[i]);
    const double modelled = t30(amplitude, rate / bin), expected = eyring(b);
    // The rendered response in the band, through an analysis filter of the test's own: the
    // bank's neighbouring bands overlap a little, and the slower one lingers in the band.
    const double rendered = t30(convolve(r.ir, octave_band_pass(kOctaveBands[b], rate, 2047)), rate);
    std::printf("%g Hz, absorption %.2f: T30 %.3f s (rendered, filtered into the band: %.3f s), Eyring with air %.3f s (%+.1f%%)\n",
                kOctaveBands[b], absorption[b], modelled, rendered, expected, 100.0 * (modelled / expected - 1.0));
    EXPECT_NEAR(modelled / expected, 1.0, 0.10) << kOctaveBands[b] << " Hz";
  }
  // Nothing before the direct sound's band-limited impulse (16 samples either side of its
  // time): every band filter is causal.
  for (std::size_t i = 0; i + 16 < r.direct_sample; ++i) ASSERT_EQ(r.ir[i], 0.0) << i;
}

TEST(AudioRoomBands, EqualBandsGiveTheBroadbandResponse) {
  // Six equal coefficients: the bank's filters sum to an impulse, so the banded rendering
  // is the broadband one (to rounding).
  Shoebox box{{3, 3, 3}, {44, 36, 28}};
  const Tree tree = shoebox_tree(box, 0.1);
  MaterialTable banded;
  banded.fallback.bands.assign(6, std::sqrt(0.7));
  const AcousticScene a(tree, banded), b(tree, scene_material(std::sqrt(0.7)));
  const Room per_band(a), broadband(b);
  RoomOptions o;
  o.rays = 2000;
  o.max_length = 0.5;
  o.threads = 1;
  const Point s{1.3, 1.4, 1.1}, l{3.1, 2.2, 1.7};
  const RoomResponse x = room_response(per_band, s, l, o), y = room_response(broadband, s, l, o);
  ASSERT_GE(x.ir.size(), y.ir.size());
  double error = 0.0, energy = 0.0;
  for (std::size_t i = 0; i < x.ir.size(); ++i) {
    const double reference = i < y.ir.size() ? y.ir[i] : 0.0;
    error += (x.ir[i] - reference) * (x.ir[i] - reference);
    energy += reference * reference;
  }
  EXPECT_LT(error / energy, 1e-12);
}

}  // namespace
