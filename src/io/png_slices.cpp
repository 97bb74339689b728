// One PNG per z slice (the reference reader's --images).
#include <filesystem>
#include <string>
#include <system_error>
#include <vector>

#include "vola/io/png_image.hpp"
#include "vola/error.hpp"
#include "vola/io/export.hpp"

namespace vola::io {

std::uint32_t write_png_slices(const Tree& tree, const std::string& directory, bool world_files) {
  if (tree.depth() > kMaxSliceDepth)
    throw OptionError("depth", "slices of depth " + std::to_string(tree.depth()) + " would be " +
                                   std::to_string(tree.side()) + " images of " + std::to_string(tree.side()) +
                                   "^2 pixels; slices stop at depth " + std::to_string(kMaxSliceDepth) +
                                   ": export a coarser copy (`depth` K)");
  std::error_code error;
  std::filesystem::create_directories(directory, error);
  if (error) throw IoError(directory + ": cannot create the directory: " + error.message());

  const std::uint64_t side = tree.side();
  // One bit per voxel, slice after slice (z-major), so that a slice's rows are
  // consecutive bits: S^3 / 8 bytes (128 MiB at depth 5).
  std::vector<std::uint64_t> bits((side * side * side + 63) / 64, 0);
  tree.for_each_voxel([&](const Voxel& v) {
    const std::uint64_t index = (v.z * side + v.y) * side + v.x;
    bits[index >> 6] |= std::uint64_t{1} << (index & 63);
  });
  const std::size_t digits = std::max<std::size_t>(3, std::to_string(side - 1).size());
  std::vector<std::uint8_t> row(side);
  for (std::uint64_t z = 0; z < side; ++z) {
    std::string number = std::to_string(z);
    number.insert(0, digits - number.size(), '0');
    const std::filesystem::path file =
        std::filesystem::path(directory) / ("depth" + std::to_string(tree.depth()) + "-" + number + ".png");
    PngImage image(file.string(), static_cast<std::uint32_t>(side), static_cast<std::uint32_t>(side), 8);
    for (std::uint64_t r = 0; r < side; ++r) {
      const std::uint64_t y = side - 1 - r;  // north up
      for (std::uint64_t x = 0; x < side; ++x) {
        const std::uint64_t index = (z * side + y) * side + x;
        row[x] = ((bits[index >> 6] >> (index & 63)) & 1u) ? 255 : 0;
      }
      image.write_row(row.data());
    }
    image.finish();
    if (world_files) write_world_file(tree, file.string());
  }
  return static_cast<std::uint32_t>(side);
}

}  // namespace vola::io
