#include "vola/io/png_decode.hpp"

#include <png.h>

#include <cerrno>
#include <csetjmp>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "vola/error.hpp"

namespace vola::io {

namespace {

// Deflate expands at most 1032:1, so a PNG of n bytes decodes to at most about 1032 n
// bytes: an image claiming more is refused before anything is allocated for it.
constexpr std::uint64_t kMaxInflation = 1032;

struct File {
  std::FILE* f = nullptr;
  ~File() {
    if (f) std::fclose(f);
  }
};

struct PngError {
  char message[256] = "libpng error";
};

void on_png_error(png_structp png, png_const_charp message) {
  auto* error = static_cast<PngError*>(png_get_error_ptr(png));
  std::snprintf(error->message, sizeof error->message, "%s", message);
  png_longjmp(png, 1);
}
void on_png_warning(png_structp, png_const_charp) {}

// setjmp/longjmp: nothing with a destructor is created between setjmp and the reads.
bool decode_png_raw(std::FILE* f, std::uint64_t file_size, DecodedPng& out, std::vector<png_bytep>& rows,
                    PngError& error, std::string& refusal) {
  png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, &error, on_png_error, on_png_warning);
  if (!png) {
    refusal = "out of memory";
    return false;
  }
  png_infop info = png_create_info_struct(png);
  if (!info) {
    png_destroy_read_struct(&png, nullptr, nullptr);
    refusal = "out of memory";
    return false;
  }
  if (setjmp(png_jmpbuf(png))) {
    png_destroy_read_struct(&png, &info, nullptr);
    return false;
  }
  png_init_io(png, f);
  png_read_info(png, info);
  const png_uint_32 width = png_get_image_width(png, info), height = png_get_image_height(png, info);
  const int color_type = png_get_color_type(png, info);
  if (color_type == PNG_COLOR_TYPE_PALETTE) png_set_palette_to_rgb(png);
  if (color_type == PNG_COLOR_TYPE_GRAY && png_get_bit_depth(png, info) < 8) png_set_expand_gray_1_2_4_to_8(png);
  png_read_update_info(png, info);
  const int bit_depth = png_get_bit_depth(png, info), channels = png_get_channels(png, info);
  const std::uint64_t row_bytes = png_get_rowbytes(png, info);
  if (std::uint64_t{height} * row_bytes > kMaxInflation * file_size + 4096) {
    png_destroy_read_struct(&png, &info, nullptr);
    refusal = "a " + std::to_string(width) + " x " + std::to_string(height) + " image cannot be stored in a file of " +
              std::to_string(file_size) + " bytes";
    return false;
  }
  out.width = width;
  out.height = height;
  out.bit_depth = bit_depth;
  out.channels = channels;
  out.bytes.resize(height * row_bytes);
  rows.resize(height);
  for (png_uint_32 y = 0; y < height; ++y) rows[y] = out.bytes.data() + y * row_bytes;
  png_read_image(png, rows.data());
  png_read_end(png, nullptr);
  png_destroy_read_struct(&png, &info, nullptr);
  return true;
}

std::uint64_t png_file_size(const std::string& path) {
  std::error_code ec;
  const auto size = std::filesystem::file_size(path, ec);
  if (ec) throw IoError(path + ": cannot open: " + ec.message());
  return size;
}

}  // namespace

DecodedPng decode_png(const std::string& path) {
  const std::uint64_t size = png_file_size(path);
  File file;
  file.f = std::fopen(path.c_str(), "rb");
  if (!file.f) throw IoError(path + ": cannot open: " + std::strerror(errno));
  std::uint8_t signature[8] = {};
  if (std::fread(signature, 1, 8, file.f) != 8 || png_sig_cmp(signature, 0, 8) != 0)
    throw FormatError(path, 0, "not a PNG file (bad signature)");
  std::rewind(file.f);
  DecodedPng out;
  std::vector<png_bytep> rows;
  PngError error;
  std::string refusal;
  if (!decode_png_raw(file.f, size, out, rows, error, refusal))
    throw FormatError(path, std::nullopt, refusal.empty() ? std::string("PNG: ") + error.message : refusal);
  return out;
}

}  // namespace vola::io
