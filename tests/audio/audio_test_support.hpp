// Helpers of the auralisation tests: shoebox rooms of voxel walls and the recordings in
// $VOLA_SHARED/data/audio.
#pragma once

#include <cstdint>
#include <vector>

#include "test_support.hpp"
#include "vola/tree.hpp"

namespace vola_audio_test {

// Walls one voxel thick on the planes x = lo[0] and x = hi[0], and so on, closing the box
// [lo, hi] (voxel indices); the interior lo+1 .. hi-1 is empty.
struct Shoebox {
  std::uint32_t lo[3];
  std::uint32_t hi[3];
  bool walls[6] = {true, true, true, true, true, true};  // -x, +x, -y, +y, -z, +z
};

// The room in a depth-4 tree (256^3) with a grid frame at the origin and voxels of
// `voxel_size` metres.
vola::Tree shoebox_tree(const Shoebox& box, double voxel_size);

// $VOLA_SHARED/data/audio.
vola_test::fs::path audio_dir();

// T30 of a response sampled at `rate`: the Schroeder curve (energy still to come, in dB
// of the total) and a least-squares line through its points between -5 and -35 dB,
// extrapolated to -60 dB.
double t30(const std::vector<double>& ir, double rate);

}  // namespace vola_audio_test

// Skips the test when the recordings are missing, fails it when CI is set.
#define VOLA_REQUIRE_AUDIO(dir_var)                                                              \
  const ::vola_test::fs::path dir_var = ::vola_audio_test::audio_dir();                          \
  if (!::vola_test::fs::is_directory(dir_var)) {                                                 \
    if (std::getenv("CI")) {                                                                     \
      ADD_FAILURE() << "audio folder " << dir_var << " is missing (CI is set; set VOLA_SHARED)"; \
      return;                                                                                    \
    }                                                                                            \
    GTEST_SKIP() << "audio folder " << dir_var << " is missing; set VOLA_SHARED to run this";     \
  }
