// The physical impulse response of a VOLA scene: what a listener hears from a source,
// level for level as the image-source method and room-acoustic theory give it.
//
// Three parts, in world units taken as metres:
//   direct:  amplitude 1 / d (1 at 1 m) after d / c, silent when the straight line crosses
//            an occupied voxel (with occlusion on, the default);
//   early:   image sources (Allen and Berkley 1979) over the scene's planar patches
//            (patches.hpp) up to `order` reflections. An image counts when the path it
//            stands for exists: traced back from the listener, each leg meets its patch's
//            plane on a voxel of that patch, and (occlusion on) every leg is free of
//            other voxels (exact voxel ray casts, raycast/). Its amplitude is
//              prod_i R_i * sqrt(1 - s) * sqrt(w_i)  /  path length,
//            R_i = the patch's pressure reflection coefficient (sqrt(1 - absorption)),
//            s = the scattering coefficient (energy the patch sends diffusely instead),
//            w_i = min(1, patch area / first Fresnel zone area at 1 kHz): a patch smaller
//            than the zone that forms a specular reflection reflects that fraction of it;
//            a wall is a full mirror whatever its voxel size;
//   late:    stochastic energy ray tracing (Vorlaender's method) over the voxels: `rays`
//            rays leave the source uniformly, lose R^2 of their energy at each hit, go
//            on specularly (probability 1 - s) or Lambert-diffusely (s) from the patch's
//            normal. At each hit the diffuse part goes straight to the listener when it
//            sees it ("diffuse rain": energy s cos(theta) / (pi D^2); whether the listener
//            sees the face hit is cast once per face, from its centre); a ray whose last
//            reflection was specular deposits energy * chord / volume when it crosses a
//            receiver sphere around the listener (its radius shrunk to clear every
//            occupied voxel). Paths the image sources already hold (purely specular, at
//            most the order searched, and the direct path) deposit nothing, so no energy
//            is counted twice. The energy per millisecond becomes noise of that energy
//            (random signs), from the earliest deposit on. Rays are traced in rounds
//            until the histogram is precise enough (RoomOptions::tail_error), at most
//            `rays`. Legs that end at the listener stop just short of it: a listener
//            standing on a face (a table top) is not hidden by the voxel under it.
// Normalisation: the source's power is that of the direct sound's 1 / d, so the tail's
// energy is on the same scale as the image sources' squared amplitudes.
// Frequency: every amplitude and energy is kept per octave band (per-band materials, air
// absorption with `air`). When the bands differ, each band's response (its arrivals as
// impulses, its tail as the one noise sequence under the band's envelope) passes through
// its filter of an octave bank that sums to an impulse (band_filters.hpp), and the six
// are added; otherwise the response is the one broadband sequence.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include "vola/audio/patches.hpp"
#include "vola/audio/response.hpp"

namespace vola::audio {

// One value per octave band of kOctaveBands (125 Hz .. 4 kHz).
using Bands = std::array<double, kOctaveBands.size()>;

struct RoomOptions {
  double sample_rate = 48000.0;    // Hz
  double speed_of_sound = 343.0;   // m/s
  int order = 3;                   // image-source reflections at most
  bool occlusion = true;           // ray casts on every leg, the direct path included
  double scattering = 0.3;         // energy fraction reflected diffusely, [0, 1]
  std::uint64_t rays = 20000;      // for the late tail, at most; 0 = no tail
  double tail_error = 0.1;         // rays are traced in rounds of 1024 until the relative
                                   // standard error of the tail's energy per 10 ms window,
                                   // root mean square over the windows down to 60 dB below
                                   // the loudest, is at most this (from the spread between
                                   // chunks of 128 rays; 2048 rays at least); 0 = all `rays`.
                                   // 0.1 is about 0.4 dB on a window's level
  double max_length = 10.0;        // s: the tail is traced at most this long
  double decay_floor_db = -70.0;   // a ray stops once its energy fell this far
  double receiver_radius = 0.5;    // m, shrunk to the listener's clearance
  std::uint64_t max_image_nodes = std::uint64_t{1} << 21;  // search budget (see image_sources)
  std::uint64_t seed = 1;          // the tail's random numbers: the same seed, the same response
  bool fractional_delay = true;    // arrivals at their exact time as band-limited impulses
                                   // (16 samples either side); false: at the nearest sample
  bool air = false;                // air absorption (ISO 9613-1, air.hpp) on every path
  double celsius = 20.0;           // the air's temperature
  double humidity = 50.0;          // its relative humidity, percent
  unsigned threads = 0;            // 0 = vola::thread_count()
  // Throws InvalidArgument naming the bad value.
  void check() const;
};

// Per band: the air's attenuation in dB per metre at the band's centre (0 without `air`).
Bands air_attenuation(const RoomOptions& options);

// A scene with its patches and their reflection coefficients. The scene must outlive it.
class Room {
 public:
  explicit Room(const AcousticScene& scene);
  const AcousticScene& scene() const noexcept { return *scene_; }
  const SurfacePatches& patches() const noexcept { return patches_; }
  // Per patch: the pressure reflection coefficient, broadband (a per-band material gives
  // the root of its bands' mean energy reflection).
  const std::vector<double>& reflection() const noexcept { return reflection_; }
  // Per patch and octave band (kOctaveBands): the band's coefficient.
  const std::vector<Bands>& band_reflection() const noexcept { return band_reflection_; }
  // Whether some material has coefficients that differ between bands.
  bool per_band() const noexcept { return per_band_; }

 private:
  const AcousticScene* scene_;
  SurfacePatches patches_;
  std::vector<double> reflection_;
  std::vector<Bands> band_reflection_;
  bool per_band_ = false;
};

struct ImageSource {
  std::vector<std::uint32_t> patches;  // reflected in, source side first
  std::vector<Point> points;           // where (world), source side first
  Point image{};                       // world
  double path = 0.0;                   // m: |image - listener|
  double amplitude = 0.0;              // broadband: the root of the bands' mean square
  Bands bands{};                       // per octave band (reflections and air)
  double delay = 0.0;                  // s
};

struct ImageSearch {
  std::vector<ImageSource> images;     // by delay
  int order = 0;                       // the order searched completely (<= options.order)
  std::uint64_t candidates = 0;        // images tried
};

// The valid image sources up to options.order, fewer when the search tree (every image in
// front of its next patch, no patch twice in a row, patches wholly behind the previous
// one skipped) would pass max_image_nodes at an order: that order and higher are left to
// the tail, and ImageSearch::order says so.
ImageSearch image_sources(const Room& room, const Point& source, const Point& listener, const RoomOptions& options);

struct LateEnergy {
  std::vector<double> energy;      // per bin: the sum of squared response samples it holds
                                   // (the bands' mean)
  std::vector<Bands> bands;        // per bin and band: the energy if every band were this one
  std::size_t bin_samples = 1;     // samples per bin (1 ms)
  std::size_t first_sample = 0;    // the earliest deposit: the tail's noise starts there
  double receiver_radius = 0.0;    // m, as used
  std::uint64_t rays = 0;          // rays traced
  double relative_error = 0.0;     // the 10 ms windows' relative standard error reached
                                   // (root mean square, as tail_error)
};

// The ray-traced energy histogram, without the paths the image sources of `order` hold.
LateEnergy late_energy(const Room& room, const Point& source, const Point& listener, int order, const RoomOptions& options);

struct RoomResponse {
  double direct_distance = 0.0;    // m
  double direct_amplitude = 0.0;   // 0 when occluded; without air absorption
  Bands direct_bands{};            // per band, with air absorption
  bool direct_blocked = false;
  std::uint32_t direct_sample = 0;
  ImageSearch early;
  LateEnergy late;
  std::vector<double> ir;          // from time 0, at options.sample_rate
};

// Throws InvalidArgument for a source or listener outside the grid, inside an occupied
// voxel, or at the same point, and for bad options.
RoomResponse room_response(const Room& room, const Point& source, const Point& listener, const RoomOptions& options);

}  // namespace vola::audio
