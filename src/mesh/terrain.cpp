#include "vola/mesh/terrain.hpp"

#include <algorithm>
#include <string>
#include <vector>

#include "vola/error.hpp"

namespace vola::mesh {

namespace {

struct Column {
  Key xy;  // key of (x, y, 0): equal for every voxel of one column
  std::uint32_t low, high;
};

// The voxel row of height `z` at the column of `at`, clamped to the grid.
std::uint32_t base_row(const Quantizer& quantizer, const Voxel& at, double z) {
  const Point centre = quantizer.center(at);
  Voxel v;
  if (quantizer.to_voxel({centre[0], centre[1], z}, v)) return v.z;
  return z < centre[2] ? 0 : side_of(quantizer.depth()) - 1;
}

}  // namespace

Tree terrain_columns(const PointCloud& surface, const Quantizer& quantizer, const TerrainOptions& options,
                     BuildReport* report) {
  const std::size_t n = surface.size();
  std::vector<Column> columns;
  columns.reserve(n);
  std::uint64_t outside = 0;
  for (std::size_t i = 0; i < n; ++i) {
    Voxel v;
    if (!quantizer.to_voxel({surface.xyz[3 * i], surface.xyz[3 * i + 1], surface.xyz[3 * i + 2]}, v)) {
      ++outside;
      continue;
    }
    const std::uint32_t base = options.surface_only ? v.z : base_row(quantizer, v, options.base);
    columns.push_back({encode(v.x, v.y, 0), std::min(v.z, base), std::max(v.z, base)});
  }
  if (!options.surface_only) {
    // Every column of one (x, y) contains the base row, so together they are one run.
    std::sort(columns.begin(), columns.end(), [](const Column& a, const Column& b) { return a.xy < b.xy; });
    std::size_t merged = 0;
    for (std::size_t i = 0; i < columns.size(); ++i) {
      if (merged && columns[merged - 1].xy == columns[i].xy) {
        columns[merged - 1].low = std::min(columns[merged - 1].low, columns[i].low);
        columns[merged - 1].high = std::max(columns[merged - 1].high, columns[i].high);
      } else {
        columns[merged++] = columns[i];
      }
    }
    columns.resize(merged);
  }
  std::uint64_t voxels = 0;
  for (const Column& c : columns) voxels += c.high - c.low + 1;
  if (voxels > options.max_voxels)
    throw InvalidArgument("terrain: the columns would hold " + std::to_string(voxels) + " voxels, more than " +
                          std::to_string(options.max_voxels) + "; ask for the surface only or a coarser grid");
  std::vector<Key> keys;
  keys.reserve(voxels);
  for (const Column& c : columns)
    for (std::uint32_t z = c.low; z <= c.high; ++z) keys.push_back(c.xy | encode(0, 0, z));
  Tree tree = build_from_keys(std::move(keys), quantizer.depth());
  tree.set_frame(quantizer.frame());
  if (report) {
    report->points_in = n;
    report->points_outside = outside;
    report->voxels = tree.voxel_count();
  }
  return tree;
}

}  // namespace vola::mesh
