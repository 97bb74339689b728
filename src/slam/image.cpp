#include "vola/slam/image.hpp"

#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>

#include "vola/error.hpp"
#include "vola/io/png_decode.hpp"
#include "vola/io/png_image.hpp"

namespace vola::slam {

void Intrinsics::check() const {
  if (!std::isfinite(fx) || !std::isfinite(fy) || fx == 0.0 || fy == 0.0 || !std::isfinite(cx) ||
      !std::isfinite(cy))
    throw InvalidArgument("intrinsics: fx and fy must be finite and non-zero, cx and cy finite");
}

namespace {

std::uint64_t file_size_of(const std::string& path) {
  std::error_code ec;
  const auto size = std::filesystem::file_size(path, ec);
  if (ec) throw IoError(path + ": cannot open: " + ec.message());
  return size;
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
  const io::DecodedPng png = io::decode_png(path);
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
  const io::DecodedPng png = io::decode_png(path);
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
