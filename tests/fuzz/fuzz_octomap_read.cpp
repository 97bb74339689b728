// Fuzz entry point of the OctoMap reader (io::read_octomap_with_liboctomap, what the
// octomap plugin runs, compiled into this program): the input is a .bt or .ot file
// (told apart by its first line), written to a scratch file. The structure check must
// stop every stream liboctomap would misread (its recursive parser has no depth limit and
// reads past the end unchecked), so a crash here is a hole in octomap_check.cpp. Only
// vola::Error may escape; what parses must be a grid: voxels inside its dims, one value
// per voxel in each column, a finite frame.
//
// Maps above 2^20 occupied cells are skipped: a few bytes can code a pruned octant of
// up to kMaxMapVoxels cells (legitimately), which would make single runs take seconds
// and gigabytes without reaching new code.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>

#include "fuzz_seeds.hpp"
#include "octomap_check.hpp"  // src/io/plugins
#include "readers.hpp"        // src/io/plugins: the reader itself, not its plugin
#include "scratch_file.hpp"
#include "vola/error.hpp"

namespace {
using vola_fuzz::check;

// False when the map codes more than 2^20 occupied cells (a damaged stream passes: the
// reader must refuse it by itself).
bool small_enough(std::span<const std::uint8_t> data) {
  try {
    const std::string_view bytes(reinterpret_cast<const char*>(data.data()), data.size());
    vola::io::check_octomap_bytes(bytes, "input", std::uint64_t{1} << 20);
  } catch (const vola::FormatError& e) {
    return e.cause().find("occupied cells") == std::string::npos;
  }
  return true;
}

void check_grid(const vola::io::VoxelGrid& grid) {
  check(std::isfinite(grid.voxel_size) && grid.voxel_size > 0.0);
  for (double o : grid.origin) check(std::isfinite(o));
  for (const vola::Voxel& v : grid.voxels) check(v.x < grid.dims[0] && v.y < grid.dims[1] && v.z < grid.dims[2]);
  for (const auto& column : grid.attributes) check(column.values.size() == grid.voxels.size());
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::span<const std::uint8_t> bytes(data, size);
  const std::string path = vola_fuzz::scratch_file("octomap", "bt", bytes);
  if (!small_enough(bytes)) return 0;
  try {
    check_grid(vola::io::read_octomap_with_liboctomap(path, true));
  } catch (const vola::Error&) {
    ++vola_fuzz::stats().refused;
    return 0;
  }
  ++vola_fuzz::stats().parsed;
  return 0;
}
