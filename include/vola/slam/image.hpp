// Depth and colour images of an RGB-D camera, the pinhole intrinsics that project into
// them, and reading/writing them: 16-bit PNG depth (value / depth_factor = metres),
// 16-bit big-endian PGM depth (the Kinect frames of slambook), 8-bit RGB(A)/grey PNG.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace vola::slam {

// Pixel (u, v) of a point (x, y, z) in camera coordinates (x right, y down, z forward
// for a positive fy) is u = fx * x / z + cx, v = fy * y / z + cy, with (0, 0) the centre
// of the top-left pixel. fy may be negative (ICL-NUIM's convention flips y).
struct Intrinsics {
  double fx = 525.0, fy = 525.0, cx = 319.5, cy = 239.5;
  // The intrinsics of an image half as wide and high (2x2 pixels become one).
  Intrinsics halved() const noexcept { return {fx / 2, fy / 2, (cx + 0.5) / 2 - 0.5, (cy + 0.5) / 2 - 0.5}; }
  // Throws InvalidArgument for a zero or non-finite focal length or a non-finite centre.
  void check() const;
};

// Depth in metres, row-major, row 0 at the top; 0 = no measurement.
struct DepthImage {
  std::uint32_t width = 0, height = 0;
  std::vector<float> metres;
  float at(std::uint32_t u, std::uint32_t v) const noexcept { return metres[std::size_t{v} * width + u]; }
};

// 8-bit RGB, row-major, 3 bytes per pixel.
struct RgbImage {
  std::uint32_t width = 0, height = 0;
  std::vector<std::uint8_t> rgb;
};

// Reads a 16-bit grey PNG or a 16-bit (maxval > 255) binary PGM ("P5"), chosen by the
// file's signature; raw value 0 stays 0, others become raw / depth_factor metres.
// Throws FormatError naming the file for anything else (8-bit depth, colour, truncated
// data, an image larger than the file can hold) and IoError when it cannot be opened.
DepthImage read_depth(const std::string& path, double depth_factor);
// Writes round(metres * depth_factor) as a 16-bit grey PNG (0 for no measurement,
// clamped to 65535). Throws IoError.
void write_depth_png(const std::string& path, const DepthImage& depth, double depth_factor);
// Reads an 8-bit or 16-bit grey, grey+alpha, RGB or RGBA PNG as 8-bit RGB.
RgbImage read_rgb_png(const std::string& path);
void write_rgb_png(const std::string& path, const RgbImage& image);

}  // namespace vola::slam
