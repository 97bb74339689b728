// An octave filter bank that sums back to an impulse: h_b = L_b - L_(b-1), with L_b a
// minimum-phase low-pass whose edge lies between band b and band b + 1 (L_(-1) = 0,
// L_5 = the unit impulse). The sum of the six telescopes to the impulse exactly, so equal
// amplitudes in every band give back the broadband signal; every h_b is causal, so a band
// never sounds before its arrival. Used to render a response whose bands differ
// (per-band materials, air absorption).
#pragma once

#include <array>
#include <vector>

#include "vola/audio/materials.hpp"

namespace vola::audio {

// The six filters for kOctaveBands at `sample_rate`, all of one length.
std::array<std::vector<double>, kOctaveBands.size()> octave_filters(double sample_rate);

}  // namespace vola::audio
