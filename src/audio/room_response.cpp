#include "vola/audio/room_response.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <span>

#include "vola/audio/air.hpp"
#include "vola/audio/band_filters.hpp"
#include "vola/audio/convolve.hpp"
#include "vola/error.hpp"
#include "option_checks.hpp"
#include "vola/raycast/world.hpp"

namespace vola::audio {

namespace {
// Half the length of a fractional-delay arrival (samples).
constexpr int kFractionalTaps = 16;
}  // namespace

void RoomOptions::check() const {
  const auto fail = &detail::refuse_option;
  detail::check_sound_options(sample_rate, speed_of_sound);
  if (!(order >= 0 && order <= 64)) fail("the image-source order must be in [0, 64]", order);
  if (!(scattering >= 0.0 && scattering <= 1.0)) fail("the scattering coefficient must be in [0, 1]", scattering);
  if (!(rays <= (std::uint64_t{1} << 32))) fail("the ray count must be at most 2^32", static_cast<double>(rays));
  if (!(tail_error >= 0.0 && tail_error < 1.0)) fail("the tail's relative error must be in [0, 1)", tail_error);
  if (!(max_length > 0.0 && max_length <= 60.0)) fail("the response length must be in (0, 60] s", max_length);
  if (!(decay_floor_db < 0.0 && decay_floor_db >= -200.0)) fail("the decay floor must be in [-200, 0) dB", decay_floor_db);
  if (!(receiver_radius > 0.0 && std::isfinite(receiver_radius))) fail("the receiver radius must be > 0", receiver_radius);
  if (!(celsius >= -20.0 && celsius <= 50.0)) fail("the air temperature must be in [-20, 50] degrees C", celsius);
  if (!(humidity >= 10.0 && humidity <= 100.0)) fail("the relative humidity must be in [10, 100] percent", humidity);
}

Bands air_attenuation(const RoomOptions& o) {
  Bands a{};
  if (o.air)
    for (std::size_t b = 0; b < a.size(); ++b) a[b] = air_attenuation_db_per_m(kOctaveBands[b], o.celsius, o.humidity);
  return a;
}

Room::Room(const AcousticScene& scene)
    : scene_(&scene), patches_(scene.tree(), scene.materials(), scene.blocks()) {
  const auto& slots = scene.materials().slots();
  for (const SurfacePatch& p : patches_.patches()) {
    const Material& m = slots[p.slot];
    double energy = 0.0;
    for (const double r : m.bands) energy += r * r;
    reflection_.push_back(std::sqrt(energy / static_cast<double>(m.bands.size())));
    Bands bands;
    for (std::size_t b = 0; b < bands.size(); ++b) bands[b] = m.per_band() ? m.bands[b] : m.bands[0];
    band_reflection_.push_back(bands);
    per_band_ = per_band_ || m.per_band();
  }
}

RoomResponse room_response(const Room& room, const Point& source, const Point& listener, const RoomOptions& o) {
  o.check();
  const AcousticScene& scene = room.scene();
  scene.check_point(source, "the source");
  scene.check_point(listener, "the listener");
  RoomResponse r;
  const double dx = source[0] - listener[0], dy = source[1] - listener[1], dz = source[2] - listener[2];
  r.direct_distance = std::sqrt(dx * dx + dy * dy + dz * dz);
  if (!(r.direct_distance > 0.0)) throw InvalidArgument("the source and the listener are at the same point");
  const double last = std::ceil(o.max_length * o.sample_rate);
  if (!(last < static_cast<double>(1u << 28))) throw InvalidArgument("the response would exceed 2^28 samples: shorten it");
  const double direct_sample = std::nearbyint(r.direct_distance / o.speed_of_sound * o.sample_rate);
  if (!(direct_sample < last))
    throw InvalidArgument("the source is further from the listener than sound travels in the response's length");
  r.direct_sample = static_cast<std::uint32_t>(direct_sample);
  if (o.occlusion) {
    const Point s = raycast::world_to_grid(scene.frame(), source), l = raycast::world_to_grid(scene.frame(), listener);
    // Up to just short of the listener: one standing on a face is not hidden by its voxel.
    r.direct_blocked =
        scene.caster().cast(raycast::Ray{s, {l[0] - s[0], l[1] - s[1], l[2] - s[2]}, 1.0 - 1e-9}).has_value();
  }
  r.direct_amplitude = r.direct_blocked ? 0.0 : 1.0 / r.direct_distance;
  const Bands air = air_attenuation(o);
  for (std::size_t b = 0; b < air.size(); ++b)
    r.direct_bands[b] = r.direct_amplitude * std::pow(10.0, -air[b] * r.direct_distance / 20.0);

  r.early = image_sources(room, source, listener, o);
  r.late = late_energy(room, source, listener, r.early.order, o);

  std::size_t length = std::size_t{r.direct_sample} + 1;
  for (const ImageSource& is : r.early.images)
    length = std::max(length, static_cast<std::size_t>(std::nearbyint(is.delay * o.sample_rate)) + 1);
  length = std::max(length, r.late.energy.size() * r.late.bin_samples);
  if (o.fractional_delay) length += kFractionalTaps;  // the last arrival's band-limited tail
  length = std::min(length, static_cast<std::size_t>(last));
  // One sign per sample for the tail, the same in every band: equal bands then add up to
  // the broadband noise exactly.
  std::vector<double> sign(length);
  std::mt19937_64 rng(o.seed ^ 0x5DEECE66Dull);
  for (double& v : sign) v = (rng() & 1) ? 1.0 : -1.0;
  // The response of one band (or broadband: band < 0): arrivals as impulses, each bin's
  // energy as the signs scaled to it (sum of squares = the bin's energy), not before the
  // earliest deposit (the first bin may start before any sound arrives).
  // An arrival at `time` (samples): at the nearest sample, or (fractional_delay) as a
  // band-limited impulse at the exact time, a windowed sinc over kFractionalTaps samples
  // either side (Blackman window, its sum 1 so the level below a few kHz is the arrival's).
  auto place = [&](std::vector<double>& h, double time, double amplitude) {
    if (!o.fractional_delay) {
      const auto n = static_cast<std::size_t>(std::nearbyint(time));
      if (n < h.size()) h[n] += amplitude;
      return;
    }
    const double base = std::floor(time), fraction = time - base;
    double taps[2 * kFractionalTaps], sum = 0.0;
    for (int k = -kFractionalTaps + 1; k <= kFractionalTaps; ++k) {
      const double x = k - fraction, pix = std::numbers::pi * x;
      const double window = 0.42 + 0.5 * std::cos(pix / kFractionalTaps) + 0.08 * std::cos(2.0 * pix / kFractionalTaps);
      taps[k + kFractionalTaps - 1] = (x == 0.0 ? 1.0 : std::sin(pix) / pix) * window;
      sum += taps[k + kFractionalTaps - 1];
    }
    for (int k = -kFractionalTaps + 1; k <= kFractionalTaps; ++k) {
      const double i = base + k;
      if (i >= 0.0 && i < static_cast<double>(h.size())) h[static_cast<std::size_t>(i)] += amplitude * taps[k + kFractionalTaps - 1] / sum;
    }
  };
  const double exact_direct = r.direct_distance / o.speed_of_sound * o.sample_rate;
  auto render = [&](int band) {
    std::vector<double> h(length, 0.0);
    const auto k = static_cast<std::size_t>(std::max(band, 0));
    place(h, exact_direct, band < 0 ? r.direct_amplitude : r.direct_bands[k]);
    for (const ImageSource& is : r.early.images) place(h, is.delay * o.sample_rate, band < 0 ? is.amplitude : is.bands[k]);
    for (std::size_t b = 0; b < r.late.energy.size(); ++b) {
      const std::size_t begin = std::max(b * r.late.bin_samples, r.late.first_sample);
      const std::size_t end = std::min(length, (b + 1) * r.late.bin_samples);
      const double energy = band < 0 ? r.late.energy[b] : r.late.bands[b][k];
      if (begin >= end || energy == 0.0) continue;
      const double a = std::sqrt(energy / static_cast<double>(end - begin));
      for (std::size_t i = begin; i < end; ++i) h[i] += a * sign[i];
    }
    return h;
  };
  if (!room.per_band() && !o.air) {
    r.ir = render(-1);
    return r;
  }
  // Bands that differ: each through its filter of the bank, added, from the first arrival
  // on (the filters are causal: FFT rounding then cannot put sound before it).
  std::size_t first = r.direct_blocked ? length : r.direct_sample;
  for (const ImageSource& is : r.early.images)
    first = std::min(first, static_cast<std::size_t>(std::nearbyint(is.delay * o.sample_rate)));
  if (!r.late.energy.empty()) first = std::min(first, r.late.first_sample);
  if (o.fractional_delay) first = first > kFractionalTaps ? first - kFractionalTaps : 0;
  const auto bank = octave_filters(o.sample_rate);
  r.ir.assign(length + bank[0].size() - 1, 0.0);
  if (first >= length) return r;
  for (std::size_t b = 0; b < bank.size(); ++b) {
    const std::vector<double> band = render(static_cast<int>(b));
    const std::vector<double> filtered = convolve(std::span<const double>(band).subspan(first), bank[b]);
    for (std::size_t i = 0; i < filtered.size() && first + i < r.ir.size(); ++i) r.ir[first + i] += filtered[i];
  }
  return r;
}

}  // namespace vola::audio
