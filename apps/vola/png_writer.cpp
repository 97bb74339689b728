#include "png_writer.hpp"

#include <png.h>

#include <cstdio>
#include <memory>

#include "vola/error.hpp"

namespace vola::cli {
namespace {

// libpng reports errors by longjmp; the rows are written with no C++ object alive
// between setjmp and the jump other than plain pointers.
void write_png(const std::string& path, std::uint32_t width, std::uint32_t height, int bit_depth, int colour_type,
               const std::uint8_t* data, std::size_t row_bytes) {
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> file(std::fopen(path.c_str(), "wb"), &std::fclose);
  if (!file) throw IoError("cannot create " + path);
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  png_infop info = png ? png_create_info_struct(png) : nullptr;
  if (!png || !info) {
    png_destroy_write_struct(&png, &info);
    throw IoError("libpng could not start writing " + path);
  }
  if (setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, &info);
    throw IoError("libpng failed writing " + path);
  }
  png_init_io(png, file.get());
  png_set_IHDR(png, info, width, height, bit_depth, colour_type, PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT,
               PNG_FILTER_TYPE_DEFAULT);
  png_write_info(png, info);
  if (bit_depth == 16) png_set_swap(png);  // our samples are little-endian in memory
  for (std::uint32_t y = 0; y < height; ++y) png_write_row(png, data + y * row_bytes);
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
  if (std::fflush(file.get()) != 0) throw IoError("cannot write " + path);
}

}  // namespace

void write_png_rgb8(const std::string& path, std::uint32_t width, std::uint32_t height,
                    const std::vector<std::uint8_t>& rgb) {
  write_png(path, width, height, 8, PNG_COLOR_TYPE_RGB, rgb.data(), std::size_t{width} * 3);
}

void write_png_gray16(const std::string& path, std::uint32_t width, std::uint32_t height,
                      const std::vector<std::uint16_t>& gray) {
  write_png(path, width, height, 16, PNG_COLOR_TYPE_GRAY, reinterpret_cast<const std::uint8_t*>(gray.data()),
            std::size_t{width} * 2);
}

}  // namespace vola::cli
