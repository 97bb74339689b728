// Top-down images: a height map, and the reference reader's occupancy map (--map); the
// world files that place them.
#include <algorithm>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "vola/io/png_image.hpp"
#include "vola/error.hpp"
#include "vola/io/export.hpp"
#include "vola/output_file.hpp"

namespace vola::io {

namespace {

void check_map_size(const Tree& tree) {
  if (tree.depth() > kMaxMapDepth)
    throw OptionError("depth", "a map of depth " + std::to_string(tree.depth()) + " would be " +
                                   std::to_string(tree.side()) + "^2 pixels; maps stop at depth " +
                                   std::to_string(kMaxMapDepth) + ": export a coarser copy (`depth` K)");
}

// Per (x, y) column, 1 + the highest occupied z, 0 for an empty column; index x + S*y.
// 16 bits hold it up to kMaxMapDepth (side 16384).
std::vector<std::uint16_t> column_tops(const Tree& tree) {
  const std::uint64_t side = tree.side();
  std::vector<std::uint16_t> tops(side * side, 0);
  tree.for_each_voxel([&](const Voxel& v) {
    std::uint16_t& top = tops[v.x + side * v.y];
    top = std::max(top, static_cast<std::uint16_t>(v.z + 1));
  });
  return tops;
}

// Rows from the top of the image (largest y) down, each filled by `pixel(x, y)`.
template <class Sample, class F>
void write_top_down(const std::string& path, std::uint64_t side, int bits, F&& pixel) {
  PngImage image(path, static_cast<std::uint32_t>(side), static_cast<std::uint32_t>(side), bits);
  std::vector<Sample> row(side);
  for (std::uint64_t r = 0; r < side; ++r) {
    const std::uint64_t y = side - 1 - r;
    for (std::uint64_t x = 0; x < side; ++x) row[x] = pixel(x, y);
    image.write_row(row.data());
  }
  image.finish();
}

}  // namespace

void write_png_height_map(const Tree& tree, const std::string& path, int bits) {
  if (bits != 8 && bits != 16) throw InvalidArgument("height map: bits must be 8 or 16, got " + std::to_string(bits));
  check_map_size(tree);
  const std::uint64_t side = tree.side();
  const std::vector<std::uint16_t> tops = column_tops(tree);
  if (bits == 16) {
    write_top_down<std::uint16_t>(path, side, 16, [&](std::uint64_t x, std::uint64_t y) { return tops[x + side * y]; });
    return;
  }
  const double step = 254.0 / static_cast<double>(side - 1);
  write_top_down<std::uint8_t>(path, side, 8, [&](std::uint64_t x, std::uint64_t y) -> std::uint8_t {
    const unsigned top = tops[x + side * y];
    return top ? static_cast<std::uint8_t>(1 + std::lround((top - 1) * step)) : 0;
  });
}

void write_png_occupancy_above(const Tree& tree, const std::string& path, std::uint32_t min_z) {
  check_map_size(tree);
  const std::uint64_t side = tree.side();
  const std::vector<std::uint16_t> tops = column_tops(tree);
  // Any voxel at z >= min_z  <=>  the highest one is there.
  write_top_down<std::uint8_t>(path, side, 8, [&](std::uint64_t x, std::uint64_t y) -> std::uint8_t {
    const unsigned top = tops[x + side * y];
    return top && top - 1 >= min_z ? 0 : 255;
  });
}

std::string world_file_path(const std::string& image_path) {
  return std::filesystem::path(image_path).replace_extension(".pgw").string();
}

std::string write_world_file(const Tree& tree, const std::string& image_path) {
  const Frame frame = tree.frame();
  const double size = frame.voxel_size;
  const double side = static_cast<double>(tree.side());
  // The centre of the top-left pixel: voxel column (0, S - 1).
  const double values[6] = {size, 0.0, 0.0, -size, frame.origin[0] + 0.5 * size, frame.origin[1] + (side - 0.5) * size};
  std::string text;
  for (const double value : values) {
    char digits[32];
    const auto result = std::to_chars(digits, digits + sizeof digits, value);  // shortest exact text
    text.append(digits, result.ptr);
    text += '\n';
  }
  const std::string path = world_file_path(image_path);
  OutputFile out(path);
  out.write(text);
  out.commit();
  return path;
}

}  // namespace vola::io
