// Whole-image PNGs for the render, plot and evaluation commands: 8-bit RGB or 16-bit grey,
// through the library's one PNG writer (vola/io/png_image.hpp).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace vola::cli {

// Throws vola::IoError when the file cannot be written.
void write_png_rgb8(const std::string& path, std::uint32_t width, std::uint32_t height,
                    const std::vector<std::uint8_t>& rgb);
void write_png_gray16(const std::string& path, std::uint32_t width, std::uint32_t height,
                      const std::vector<std::uint16_t>& gray);

}  // namespace vola::cli
