// The impulse response from a sound source to a listener inside a VOLA scene, the
// paper's SonifEye (section IV), in three steps:
//   1. threshold():  every reflecting surface voxel (surface.hpp) gives the path
//      source -> voxel -> listener; voxels with the same delay sample and the same
//      attenuation bin are counted together ("thresholding the environment").
//   2. make_filter(): the bins, plus the direct sound, become an FIR filter (the
//      impulse response) at the sample rate.
//   3. convolve() (convolve.hpp): the dry source through the filter.
//
// The model, in world units taken as metres (the scene's frame):
//   direct:      delay d / c, amplitude 1 / d (1 at 1 m), none when the straight line
//                from source to listener passes through an occupied voxel;
//   reflection:  a surface voxel reflects through each exposed face (empty neighbour)
//                that both source and listener are in front of; it reflects at the
//                centre of those faces (the wall's surface, not the voxel's centre) as
//                a patch of the voxel's face area A: amplitude
//                R * sqrt(A / pi) / (r1 * r2), delay (r1 + r2) / c, where r1, r2 are the
//                two legs and R the voxel's reflection coefficient (materials.hpp);
//                optionally only when both legs are free of other voxels (raycast);
//   binning:     delay rounded to the nearest sample, amplitude to the nearest
//                bin_width_db decibels; each bin adds count * its amplitude to the
//                filter at its delay. Per-band materials get their own bins, and their
//                bins pass through a minimum-phase FIR shaped by the band coefficients
//                (it starts at the arrival: no pre-echo).
// Reflections arriving later than the straight-line travel time plus the reflection
// window are left out (the late reverberation is not modelled).
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "vola/audio/materials.hpp"
#include "vola/audio/surface.hpp"
#include "vola/frame.hpp"
#include "vola/raycast/ray_caster.hpp"
#include "vola/tree.hpp"

namespace vola::audio {

struct ResponseOptions {
  double sample_rate = 48000.0;     // Hz: the dry recording's rate in `vola sonify`
  double speed_of_sound = 343.0;    // m/s (air at 20 degrees C)
  double reflection_window = 0.1;   // s after the straight-line arrival: early reflections
  double bin_width_db = 0.1;        // attenuation bin width in dB (max error +-0.05 dB)
  double floor_db = -120.0;         // reflections weaker than this (re 1 at 1 m) are dropped
  bool visibility = false;          // keep only voxels seen from both ends (two rays each)
  unsigned threads = 0;             // 0 = vola::thread_count() (every hardware thread unless set)
  // Throws InvalidArgument naming the bad value.
  void check() const;
};

// The amplitude of each attenuation level, values[level - low] = 10^(-level * width / 20).
struct LevelAmplitudes {
  std::int32_t low = 0;
  std::vector<double> values;
};

// A tree with its reflection coefficients, ready for responses. The tree must outlive it.
class AcousticScene {
 public:
  AcousticScene(const Tree& tree, const MaterialTable& materials);
  ~AcousticScene();

  const Tree& tree() const noexcept { return *tree_; }
  const Frame& frame() const noexcept { return frame_; }
  const VoxelMaterials& materials() const noexcept { return materials_; }
  const std::vector<LeafBlock>& blocks() const noexcept { return blocks_; }
  // The blocks holding surface voxels, with their exposed faces (found once, here).
  const std::vector<SurfaceBlock>& surface() const noexcept { return surface_; }
  const raycast::RayCaster& caster() const noexcept { return caster_; }
  // Throws InvalidArgument when `p` is not finite, lies outside the grid or inside an occupied voxel;
  // `what` names the point ("source 1", "listener").
  void check_point(const Point& p, const std::string& what) const;
  // Every level a response with these options can have (one pow each), made on first use
  // per (bin width, floor) and kept, so make_filter() costs no pow per call. Empty values
  // when the levels are too many to tabulate (a bin width far below 0.001 dB). Thread-safe.
  std::shared_ptr<const LevelAmplitudes> level_amplitudes(const ResponseOptions& options) const;

 private:
  struct AmplitudeCache;
  const Tree* tree_;
  Frame frame_;
  VoxelMaterials materials_;
  std::vector<LeafBlock> blocks_;
  std::vector<SurfaceBlock> surface_;
  raycast::RayCaster caster_;
  std::unique_ptr<AmplitudeCache> amplitude_cache_;
};

// One reflecting voxel's path, before binning.
struct Reflection {
  SurfaceVoxel voxel;
  Point point{};            // where it reflects (world)
  double path = 0.0;        // r1 + r2 (m)
  double amplitude = 0.0;   // R * sqrt(A / pi) / (r1 * r2), R = 1 for per-band materials
  std::uint32_t sample = 0; // round(path / c * sample_rate)
  std::uint16_t slot = 0;   // material slot (VoxelMaterials)
};

struct Bin {
  std::uint16_t kernel = 0;  // 0: broadband (coefficient in the amplitude); k: per-band material k
  std::uint32_t sample = 0;
  std::int32_t level = 0;    // attenuation in bin_width_db steps: amplitude 10^(-level * width / 20)
  std::uint64_t count = 0;
  friend bool operator==(const Bin&, const Bin&) = default;
};

// Step 1's result for one source.
struct Thresholded {
  double direct_distance = 0.0;     // m
  std::uint32_t direct_sample = 0;
  double direct_amplitude = 0.0;    // 0 when the line of sight is blocked
  bool direct_blocked = false;
  std::uint64_t reflectors = 0;     // voxels binned
  std::vector<Bin> bins;            // sorted by (kernel, sample, level)
};

Thresholded threshold(const AcousticScene& scene, const Point& source, const Point& listener,
                      const ResponseOptions& options);
// Step 2: the impulse response, starting at time 0 (sample n = n / sample_rate seconds).
// The bins must be sorted as threshold() leaves them, and made with the same bin width and
// floor: a bin past its kernel's last sample or with a level outside those options throws
// InvalidArgument; a bin of one kernel among another's is not detected (a wrong filter).
std::vector<double> make_filter(const AcousticScene& scene, const Thresholded& response,
                                const ResponseOptions& options);
// Every reflecting voxel's path in key order, unbinned (what threshold() bins).
std::vector<Reflection> reflections(const AcousticScene& scene, const Point& source, const Point& listener,
                                    const ResponseOptions& options);

// The minimum-phase FIR (about 1/60 s long, starting at tap 0) whose magnitude follows a
// per-band material's coefficients, interpolated linearly over log frequency and held
// flat below 125 Hz and above 4 kHz.
std::vector<double> band_kernel(const Material& material, double sample_rate);

}  // namespace vola::audio
