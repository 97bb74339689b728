// The entry point of libvola_opencv.so: ORB keypoints through OpenCV (src/plugin/plugin.hpp
// says why it is a plugin: OpenCV's libraries added 6-8 MiB to every vola process, though
// only `vola fuse` with colour frames detects features). features.cpp calls it.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "../plugin/plugin.hpp"

namespace vola::slam::plugin {

struct OrbKeypoint {
  float x = 0.0f, y = 0.0f;                 // pixel position
  std::array<std::uint8_t, 32> descriptor{};  // 256-bit ORB descriptor, OpenCV's byte order
};

// ORB (max_features, scale 1.2, 8 levels, Harris score, FAST threshold) on a grey image of
// width x height bytes, row by row.
using DetectOrbEntry = void (*)(const std::uint8_t* grey, std::uint32_t width, std::uint32_t height, int max_features,
                                int fast_threshold, std::vector<OrbKeypoint>& out, vola::plugin::PluginFailure& failure);
inline constexpr const char* kDetectOrbSymbol = "vola_plugin_detect_orb";

}  // namespace vola::slam::plugin
