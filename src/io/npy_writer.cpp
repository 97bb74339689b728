// NPY dense occupancy grid: uint8 0/1 of shape (S, S, S), index [x, y, z].
#include <string>
#include <vector>

#include "vola/output_file.hpp"
#include "vola/error.hpp"
#include "vola/io/export.hpp"

namespace vola::io {

namespace {

// NPY format version 1.0: magic, header length, a Python dict literal padded with
// spaces and ended by a newline so that the data starts at a multiple of 64 bytes.
std::string npy_header(std::uint64_t side) {
  const std::string s = std::to_string(side);
  std::string dict = "{'descr': '|u1', 'fortran_order': False, 'shape': (" + s + ", " + s + ", " + s + "), }";
  const std::size_t unpadded = 10 + dict.size() + 1;
  dict.append((64 - unpadded % 64) % 64, ' ');
  dict += '\n';
  std::string header("\x93NUMPY\x01\x00", 8);
  header += static_cast<char>(dict.size() & 0xFF);
  header += static_cast<char>(dict.size() >> 8);
  return header + dict;
}

}  // namespace

void write_npy_grid(const Tree& tree, const std::string& path) {
  if (tree.depth() > kMaxNpyDepth)
    throw OptionError("depth", "a dense grid of depth " + std::to_string(tree.depth()) + " has " +
                                   std::to_string(tree.side()) + "^3 cells; NPY export stops at depth " +
                                   std::to_string(kMaxNpyDepth) + " (1 GiB): export a coarser copy (`depth` K)");
  const std::uint64_t side = tree.side();
  // One bit per cell in the array's own order, then expanded a run of z at a time:
  // S^3 / 8 bytes of memory rather than S^3.
  std::vector<std::uint64_t> bits((side * side * side + 63) / 64, 0);
  tree.for_each_voxel([&](const Voxel& v) {
    const std::uint64_t index = (v.x * side + v.y) * side + v.z;
    bits[index >> 6] |= std::uint64_t{1} << (index & 63);
  });
  OutputFile out(path);
  out.write(npy_header(side));
  std::vector<std::uint8_t> run(side);
  for (std::uint64_t row = 0; row < side * side; ++row) {
    for (std::uint64_t z = 0; z < side; ++z) {
      const std::uint64_t index = row * side + z;
      run[z] = static_cast<std::uint8_t>((bits[index >> 6] >> (index & 63)) & 1u);
    }
    out.write(run.data(), run.size());
  }
  out.commit();
}

}  // namespace vola::io
