// Reading PNG images through libpng (the writer is png_image.hpp): SLAM's depth and
// colour frames, ROS maps. A file is refused before anything is allocated for an image
// it cannot hold (deflate expands at most 1032:1).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace vola::io {

// The decoded PNG: 8 or 16 bits, 1-4 channels, rows packed (16-bit samples big-endian
// as PNG stores them).
struct DecodedPng {
  std::uint32_t width = 0, height = 0;
  int bit_depth = 0, channels = 0;
  std::vector<std::uint8_t> bytes;
};

// The image at `path`, palette and sub-byte grey expanded to 8 bits. FormatError (the
// file, and what libpng said) for a file that is not a PNG or is damaged.
DecodedPng decode_png(const std::string& path);

}  // namespace vola::io
