// Fractional-delay arrivals: an arrival between two samples is rendered as a band-limited
// impulse at its exact time. Its spectrum, computed here from the samples, must have the
// arrival's level (flat to 0.1 dB up to 0.3 of the sample rate: no loss, no aliased image)
// and the phase of the exact delay; rounding to the nearest sample misses that phase.
#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <cstdio>
#include <numbers>

#include "vola/audio/room_response.hpp"
#include "vola/builder.hpp"

namespace {

using namespace vola;
using namespace vola::audio;

TEST(AudioFractionalDelay, AnArrivalBetweenSamplesKeepsItsLevelAndExactPhase) {
  // Free field: one voxel far away in a corner of the grid.
  const std::vector<Voxel> corner{Voxel{0, 0, 0}};
  Tree tree = build_from_voxels(corner, 3);
  tree.set_frame(Frame{Quantization::grid, {0, 0, 0}, 0.25});
  const AcousticScene scene(tree, scene_material(0.0));
  const Room room(scene);
  RoomOptions o;
  o.rays = 0;
  o.order = 0;
  o.max_length = 0.1;
  // 3.12 m: 436.62 samples at 48 kHz.
  const Point listener{8.0, 8.0, 8.0}, source{11.12, 8.0, 8.0};
  const double delay = 3.12 / o.speed_of_sound * o.sample_rate;
  ASSERT_GT(std::abs(delay - std::nearbyint(delay)), 0.3);
  for (const bool fractional : {true, false}) {
    o.fractional_delay = fractional;
    const RoomResponse r = room_response(room, source, listener, o);
    double worst_db = 0.0, worst_phase = 0.0;
    for (const double f : {0.01, 0.05, 0.1, 0.2, 0.3}) {
      std::complex<double> h = 0.0;
      for (std::size_t n = 0; n < r.ir.size(); ++n) h += r.ir[n] * std::polar(1.0, -2.0 * std::numbers::pi * f * static_cast<double>(n));
      // Remove the exact delay: what is left is the arrival's amplitude, real and positive.
      const std::complex<double> aligned = h * std::polar(1.0, 2.0 * std::numbers::pi * f * delay);
      worst_db = std::max(worst_db, std::abs(20.0 * std::log10(std::abs(aligned) * 3.12)));
      worst_phase = std::max(worst_phase, std::abs(std::arg(aligned)));
    }
    if (fractional) {
      EXPECT_LT(worst_db, 0.1);
      EXPECT_LT(worst_phase, 1e-3);
    } else {
      EXPECT_GT(worst_phase, 0.5) << "rounding to a sample should miss the phase at high frequencies";
    }
    std::printf("%s: level within %.4f dB, phase within %.2e rad up to 0.3 fs\n", fractional ? "fractional delay" : "nearest sample",
                worst_db, worst_phase);
  }
}

}  // namespace
