// Fuzz entry point of the PLY, PCD, KITTI, NPY, binvox, LAS and text readers: the first
// byte picks the reader (modulo 7), the rest is the file. Only vola::Error may escape a reader;
// whatever parses must be consistent (counts, sizes, cells inside the grid), and a
// small binvox grid must survive write -> read unchanged.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <span>
#include <vector>

#include "fuzz_seeds.hpp"
#include "scratch_file.hpp"
#include "vola/io/binvox.hpp"
#include "vola/io/kitti.hpp"
#include "vola/io/las.hpp"
#include "vola/io/text_points.hpp"
#include "vola/io/npy.hpp"
#include "vola/io/pcd.hpp"
#include "vola/io/ply.hpp"
#include "vola/vola.hpp"

namespace {

using vola_fuzz::check;

void check_cloud(const vola::PointCloud& cloud) {
  check(cloud.xyz.size() % 3 == 0);
  check(cloud.payload.empty() || cloud.payload.size() == cloud.size());
  for (const auto& a : cloud.attributes) check(a.values.size() == cloud.size());
}

void check_grid(const vola::io::VoxelGrid& grid) {
  for (const auto& v : grid.voxels) check(v.x < grid.dims[0] && v.y < grid.dims[1] && v.z < grid.dims[2]);
  const std::uint32_t largest = std::max({grid.dims[0], grid.dims[1], grid.dims[2]});
  if (largest > 64) return;
  // Small grids: build a tree, write it as binvox and read it back.
  const vola::Tree tree = vola::build_from_voxels(grid.voxels, 3);
  const auto back = vola::io::parse_binvox(vola::io::serialize_binvox(tree), "rewritten");
  check(back.voxels.size() == tree.voxel_count());
  check(vola::build_from_voxels(back.voxels, 3).keys() == tree.keys());
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const std::span<const std::uint8_t> file(data + 1, size - 1);
  vola::io::InputOptions options;
  options.payload = true;
  try {
    switch (data[0] % 7) {
      case 0: {
        const vola::io::Input in = vola::io::parse_ply(file, "fuzz.ply", options);
        check_cloud(in.cloud);
        break;
      }
      case 1: check_cloud(vola::io::parse_pcd(file, "fuzz.pcd", options)); break;
      case 2:
        check_cloud(vola::io::parse_kitti(file, "fuzz.bin", options));
        check_cloud(vola::io::parse_nuscenes(file, "fuzz.pcd.bin", options));
        break;
      case 3: {
        const vola::io::Input in = vola::io::npy_input(vola::io::parse_npy(file, "fuzz.npy"), "fuzz.npy", options);
        check_cloud(in.cloud);
        if (in.grid) check_grid(*in.grid);
        break;
      }
      case 4: check_grid(vola::io::parse_binvox(file, "fuzz.binvox")); break;
      case 6: {
        // The text reader reads files: one temporary file per input, columns chosen so
        // that payload bytes and an attribute are parsed too.
        const std::string path = vola_fuzz::scratch_file("text", "xyz", file);
        vola::io::TextColumns columns;
        columns.payload = {3};
        columns.attributes.push_back({"a", vola::ValueType::f32, vola::Reduction::mean, {}});
        columns.attribute_columns = {4};
        check_cloud(vola::io::read_text_points(path, columns));
        break;
      }
      default: {
        vola::io::LasReader reader(file, "fuzz.las");
        const auto& header = reader.header();
        vola::io::LasChunk chunk;
        std::uint64_t points = 0;
        while (const std::size_t n = reader.read(chunk, 4096)) {
          check(chunk.size() == n && chunk.classification.size() == n);
          points += n;
        }
        check(points == header.point_count);
        reader.rewind();
        check_cloud(vola::io::las_points(reader, true, true));
        break;
      }
    }
  } catch (const vola::Error&) {
    ++vola_fuzz::stats().refused;
    return 0;  // refusing bad bytes with the library's error is the expected outcome
  }
  ++vola_fuzz::stats().parsed;
  return 0;
}
