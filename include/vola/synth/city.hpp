// A generated city block, the project's own demo and test data: a gently sloping
// ground with noise, a grid of box buildings (walls and flat roofs), and trees
// (trunk plus a foliage crown), sampled like an aerial-plus-street LIDAR survey.
// Each point carries intensity and an ASPRS class (2 ground, 5 high vegetation,
// 6 building). Deterministic for a given seed.
#pragma once

#include <cstdint>
#include <functional>

#include "vola/frame.hpp"

namespace vola::synth {

struct CityPoint {
  double x, y, z;
  std::uint16_t intensity;
  std::uint8_t classification;
};

struct CityOptions {
  std::uint64_t points = 1'000'000;
  std::uint64_t seed = 1;
  double size = 200.0;             // metres, square
  Point origin{500000.0, 5000000.0, 100.0};  // UTM-like easting, northing, height
};

// Calls `emit` once per point, streaming: nothing is stored.
void generate_city(const CityOptions& options, const std::function<void(const CityPoint&)>& emit);

}  // namespace vola::synth
