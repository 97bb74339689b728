#include "vola/slam/image.hpp"

#include <png.h>

#include <cmath>
#include <csetjmp>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>

#include "vola/error.hpp"
#include "vola/io/png_image.hpp"

namespace vola::slam {

void Intrinsics::check() const {
  if (!std::isfinite(fx) || !std::isfinite(fy) || fx == 0.0 || fy == 0.0 || !std::isfinite(cx) ||
      !std::isfinite(cy))
    throw InvalidArgument("intrinsics: fx and fy must be finite and non-zero, cx and cy finite");
}

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

std::uint64_t file_size_of(const std::string& path) {
  std::error_code ec;
  const auto size = std::filesystem::file_size(path, ec);
  if (ec) throw IoError(path + ": cannot open: " + ec.message());
  return size;
}

struct PngError {
  char message[256] = "libpng error";
};

void on_png_error(png_structp png, png_const_charp message) {
  auto* error = static_cast<PngError*>(png_get_error_ptr(png));
  std::snprintf(error->message, sizeof error->message, "%s", message);
  png_longjmp(png, 1);
}
void on_png_warning(png_structp, png_const_charp) {}

// The decoded PNG: 8 or 16 bits, 1-4 channels, rows packed (16-bit samples big-endian
// as PNG stores them).
struct DecodedPng {
  std::uint32_t width = 0, height = 0;
  int bit_depth = 0, channels = 0;
  std::vector<std::uint8_t> bytes;
};

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
    refusal = "a " + std::to_string(width) + " x " + std::to_string(height) +
              " image cannot be stored in a file of " + std::to_string(file_size) + " bytes";
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

DecodedPng decode_png(const std::string& path) {
  const std::uint64_t size = file_size_of(path);
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

DepthImage read_pgm_depth(const std::string& path, const std::vector<std::uint8_t>& bytes, double factor) {
  // Header: "P5" whitespace width whitespace height whitespace maxval, one whitespace,
  // then the samples; '#' starts a comment up to the end of the line.
  std::size_t at = 2;
  auto next_number = [&](const char* what) -> std::uint64_t {
    while (at < bytes.size()) {
      if (bytes[at] == '#') {
        while (at < bytes.size() && bytes[at] != '\n') ++at;
      } else if (std::isspace(bytes[at])) {
        ++at;
      } else {
        break;
      }
    }
    const std::size_t start = at;
    std::uint64_t value = 0;
    while (at < bytes.size() && bytes[at] >= '0' && bytes[at] <= '9' && at - start < 10)
      value = value * 10 + (bytes[at++] - '0');
    if (at == start) throw FormatError(path, start, std::string("PGM: expected the ") + what);
    return value;
  };
  const std::uint64_t width = next_number("width"), height = next_number("height"), maxval = next_number("maxval");
  if (at >= bytes.size() || !std::isspace(bytes[at])) throw FormatError(path, at, "PGM: no whitespace after maxval");
  ++at;
  if (maxval <= 255 || maxval > 65535)
    throw FormatError(path, std::nullopt, "PGM: depth needs 16-bit samples (maxval 256..65535), found maxval " +
                                              std::to_string(maxval));
  if (width == 0 || height == 0) throw FormatError(path, std::nullopt, "PGM: empty image");
  // Sizes of up to ten digits each: width * height * 2 could wrap around 64 bits, so the
  // samples the file holds are compared by division.
  const std::uint64_t samples = (bytes.size() - at) / 2;
  if (width > std::numeric_limits<std::uint32_t>::max() || height > std::numeric_limits<std::uint32_t>::max() ||
      height > samples / width)
    throw FormatError(path, bytes.size(), "PGM: truncated: " + std::to_string(width) + " x " + std::to_string(height) +
                                              " 16-bit samples need more than the " + std::to_string(bytes.size() - at) +
                                              " bytes after the header");
  DepthImage image;
  image.width = static_cast<std::uint32_t>(width);
  image.height = static_cast<std::uint32_t>(height);
  image.metres.resize(width * height);
  for (std::size_t i = 0; i < image.metres.size(); ++i) {
    const unsigned raw = unsigned{bytes[at + 2 * i]} << 8 | bytes[at + 2 * i + 1];
    image.metres[i] = raw == 0 ? 0.0f : static_cast<float>(raw / factor);
  }
  return image;
}

}  // namespace

DepthImage read_depth(const std::string& path, double depth_factor) {
  if (!(depth_factor > 0.0) || !std::isfinite(depth_factor))
    throw InvalidArgument("depth factor must be positive and finite");
  std::uint8_t signature[2] = {};
  {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw IoError(path + ": cannot open");
    in.read(reinterpret_cast<char*>(signature), 2);
  }
  if (signature[0] == 'P' && signature[1] == '5') {
    const std::uint64_t size = file_size_of(path);
    std::vector<std::uint8_t> bytes(size);
    std::ifstream in(path, std::ios::binary);
    in.read(reinterpret_cast<char*>(bytes.data()), static_cast<std::streamsize>(size));
    if (!in) throw IoError(path + ": read failed");
    return read_pgm_depth(path, bytes, depth_factor);
  }
  const DecodedPng png = decode_png(path);
  if (png.bit_depth != 16 || png.channels != 1)
    throw FormatError(path, std::nullopt, "depth PNG must be 16-bit grey, found " + std::to_string(png.bit_depth) +
                                              "-bit with " + std::to_string(png.channels) + " channel(s)");
  DepthImage image;
  image.width = png.width;
  image.height = png.height;
  image.metres.resize(std::size_t{png.width} * png.height);
  for (std::size_t i = 0; i < image.metres.size(); ++i) {
    const unsigned raw = unsigned{png.bytes[2 * i]} << 8 | png.bytes[2 * i + 1];
    image.metres[i] = raw == 0 ? 0.0f : static_cast<float>(raw / depth_factor);
  }
  return image;
}

void write_depth_png(const std::string& path, const DepthImage& depth, double depth_factor) {
  std::vector<std::uint16_t> samples(depth.metres.size());
  for (std::size_t i = 0; i < depth.metres.size(); ++i) {
    const double m = depth.metres[i];
    const double raw = (m > 0.0 && std::isfinite(m)) ? std::min(65535.0, std::round(m * depth_factor)) : 0.0;
    samples[i] = static_cast<std::uint16_t>(raw);
  }
  io::write_png(path, depth.width, depth.height, reinterpret_cast<const std::uint8_t*>(samples.data()), 16,
                io::PngColour::grey);
}

RgbImage read_rgb_png(const std::string& path) {
  const DecodedPng png = decode_png(path);
  RgbImage image;
  image.width = png.width;
  image.height = png.height;
  image.rgb.resize(std::size_t{png.width} * png.height * 3);
  const std::size_t sample_bytes = png.bit_depth == 16 ? 2 : 1;
  const std::size_t pixel_bytes = sample_bytes * static_cast<std::size_t>(png.channels);
  const bool grey = png.channels <= 2;
  for (std::size_t i = 0; i < std::size_t{png.width} * png.height; ++i) {
    const std::uint8_t* p = png.bytes.data() + i * pixel_bytes;  // 16-bit: high byte first
    for (int c = 0; c < 3; ++c) image.rgb[3 * i + c] = p[(grey ? 0 : c) * sample_bytes];
  }
  return image;
}

void write_rgb_png(const std::string& path, const RgbImage& image) {
  io::write_png(path, image.width, image.height, image.rgb.data(), 8, io::PngColour::rgb);
}

}  // namespace vola::slam
