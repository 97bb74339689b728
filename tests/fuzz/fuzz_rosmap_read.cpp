// Fuzz entry point of the ROS map reader (src/io/ros_map_read.cpp): the input is the
// map's YAML, a zero byte, then its PGM image; both are written to a scratch folder of
// this process (map.yaml and map.pgm) and read as one layer and as columns. Only
// vola::Error may escape; every voxel lies inside the grid, the columns are the layer's
// cells repeated.
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>


#include "fuzz_seeds.hpp"
#include "scratch_file.hpp"
#include "vola/error.hpp"
#include "vola/io/ros_map.hpp"

namespace {

namespace fs = std::filesystem;
using vola_fuzz::check;

const fs::path& map_folder() {
  static const fs::path folder = [] {
    const fs::path f = vola_fuzz::scratch_folder("rosmap");
    fs::create_directories(f);
    return f;
  }();
  return folder;
}

void check_grid(const vola::io::VoxelGrid& grid) {
  for (const auto& v : grid.voxels) check(v.x < grid.dims[0] && v.y < grid.dims[1] && v.z < grid.dims[2]);
  check(grid.voxel_size > 0.0 && grid.fixed_voxel_size);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view input(reinterpret_cast<const char*>(data), size);
  const std::size_t split = input.find('\0');
  const fs::path folder = map_folder();
  vola_fuzz::write_scratch(folder / "map.yaml", input.substr(0, split));
  vola_fuzz::write_scratch(folder / "map.pgm", split == std::string_view::npos ? std::string_view() : input.substr(split + 1));
  const std::string yaml = (folder / "map.yaml").string();
  try {
    const vola::io::VoxelGrid layer = vola::io::read_ros_map(yaml, 0.0);
    check_grid(layer);
    check(layer.dims[2] == 1);
    const vola::io::VoxelGrid columns = vola::io::read_ros_map(yaml, 2.5 * layer.voxel_size);
    check_grid(columns);
    check(columns.voxels.size() == 3 * layer.voxels.size());
  } catch (const vola::Error&) {
    ++vola_fuzz::stats().refused;
    return 0;
  }
  ++vola_fuzz::stats().parsed;
  return 0;
}
