// The entry points of libvola_opencv.so: ORB and SIFT keypoints through OpenCV (src/plugin/plugin.hpp
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

struct SiftKeypoint {
  float x = 0.0f, y = 0.0f;
  std::array<std::uint8_t, 128> descriptor{};  // OpenCV's SIFT descriptor (whole numbers 0..255)
};

// SIFT (OpenCV's defaults but the contrast threshold; at most max_features, the
// strongest) on a grey image: slower than ORB, but it matches across wider changes of
// viewpoint and scale, so the tracker uses it only where ORB fails.
using DetectSiftEntry = void (*)(const std::uint8_t* grey, std::uint32_t width, std::uint32_t height, int max_features,
                                 double contrast_threshold, std::vector<SiftKeypoint>& out,
                                 vola::plugin::PluginFailure& failure);
inline constexpr const char* kDetectSiftSymbol = "vola_plugin_detect_sift";

}  // namespace vola::slam::plugin
