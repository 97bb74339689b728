#include "png_writer.hpp"

#include "vola/io/png_image.hpp"

namespace vola::cli {

void write_png_rgb8(const std::string& path, std::uint32_t width, std::uint32_t height,
                    const std::vector<std::uint8_t>& rgb) {
  io::write_png(path, width, height, rgb.data(), 8, io::PngColour::rgb);
}

void write_png_gray16(const std::string& path, std::uint32_t width, std::uint32_t height,
                      const std::vector<std::uint16_t>& gray) {
  io::write_png(path, width, height, reinterpret_cast<const std::uint8_t*>(gray.data()), 16, io::PngColour::grey);
}

}  // namespace vola::cli
