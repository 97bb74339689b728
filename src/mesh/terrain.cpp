#include "vola/mesh/terrain.hpp"

#include <algorithm>
#include <cmath>
#include <span>
#include <string>
#include <vector>

#include "vola/error.hpp"

namespace vola::mesh {

namespace {

struct Column {
  Key xy;  // key of (x, y, 0): equal for every voxel of one column
  std::uint32_t low, high;
};

// The voxel row of height `base` under the point `p` (itself inside the grid), clamped
// to the grid: when (x, y, base) falls outside, only its height can be out, below the
// grid if it is below p.
std::uint32_t base_row(const Quantizer& quantizer, const Point& p, double base) {
  Voxel v;
  if (quantizer.to_voxel({p[0], p[1], base}, v)) return v.z;
  return base < p[2] ? 0 : side_of(quantizer.depth()) - 1;
}

// Emits the sparse levels of a set of columns straight from the columns, depth first in
// key order (like the solid fill), so that memory follows the tree, not the voxels.
// Columns are sorted by xy key, one per (x, y), and all contain one common row (the
// base): then the columns under any block of (x, y) together fill exactly the rows
// [lowest low, highest high], and a cell is occupied iff that run meets its rows.
class ColumnLevels {
 public:
  ColumnLevels(std::span<const Column> columns, int depth)
      : columns_(columns), depth_(depth), levels_(static_cast<std::size_t>(depth)) {}

  Tree tree() {
    levels_[0].push_back(block_word(0, {0, 0, 0}, 0, columns_.size()));
    std::vector<std::uint64_t> words;
    for (const auto& level : levels_) words.insert(words.end(), level.begin(), level.end());
    return Tree::from_levels(depth_, false, std::move(words), "terrain columns");
  }

 private:
  // The word of the block whose cells at `level` are 4 * parent + (0..3) per axis, for
  // the columns [begin, end) under the parent; non-empty children's blocks go to the
  // deeper levels first.
  std::uint64_t block_word(int level, const Voxel& parent, std::size_t begin, std::size_t end) {
    const unsigned shift = 2u * static_cast<unsigned>(depth_ - 1 - level);  // cell = 4^shift voxels per axis
    // The columns of each of the 16 (x, y) children: consecutive, as the xy keys sort by
    // this level's digit within the parent.
    std::size_t split[17];
    split[0] = begin;
    for (unsigned xy = 0; xy < 16; ++xy) {
      const auto digit = [&](const Column& c) { return static_cast<unsigned>(c.xy >> (3 * shift)) & 15u; };
      split[xy + 1] = static_cast<std::size_t>(
          std::partition_point(columns_.begin() + static_cast<std::ptrdiff_t>(split[xy]),
                               columns_.begin() + static_cast<std::ptrdiff_t>(end),
                               [&](const Column& c) { return digit(c) <= xy; }) -
          columns_.begin());
    }
    // The run of rows each (x, y) child's columns fill.
    std::uint32_t low[16], high[16];
    for (unsigned xy = 0; xy < 16; ++xy) {
      if (split[xy] == split[xy + 1]) continue;
      low[xy] = columns_[split[xy]].low;
      high[xy] = columns_[split[xy]].high;
      for (std::size_t i = split[xy] + 1; i < split[xy + 1]; ++i) {
        low[xy] = std::min(low[xy], columns_[i].low);
        high[xy] = std::max(high[xy], columns_[i].high);
      }
    }
    // Children in bit order (x + 4y + 16z), as each level stores them.
    std::uint64_t word = 0;
    for (unsigned dz = 0; dz < 4; ++dz) {
      const std::uint32_t cz = 4 * parent.z + dz;
      const std::uint64_t rows_from = std::uint64_t{cz} << shift, rows_to = ((std::uint64_t{cz} + 1) << shift) - 1;
      for (unsigned xy = 0; xy < 16; ++xy) {
        if (split[xy] == split[xy + 1] || high[xy] < rows_from || low[xy] > rows_to) continue;
        const unsigned bit = xy + 16 * dz;
        if (level == depth_ - 1) {
          word |= std::uint64_t{1} << bit;
          continue;
        }
        const Voxel child{4 * parent.x + (xy & 3u), 4 * parent.y + (xy >> 2), cz};
        const std::uint64_t child_word = block_word(level + 1, child, split[xy], split[xy + 1]);
        if (child_word) {
          word |= std::uint64_t{1} << bit;
          levels_[static_cast<std::size_t>(level + 1)].push_back(child_word);
        }
      }
    }
    return word;
  }

  std::span<const Column> columns_;
  int depth_;
  std::vector<std::vector<std::uint64_t>> levels_;
};

}  // namespace

Tree terrain_columns(const PointCloud& surface, const Quantizer& quantizer, const TerrainOptions& options,
                     BuildReport* report) {
  const std::size_t n = surface.size();
  std::vector<Column> columns;
  columns.reserve(n);
  std::uint64_t outside = 0;
  if (!options.surface_only && !std::isfinite(options.base))
    throw InvalidArgument("terrain: the base height must be a finite number");
  for (std::size_t i = 0; i < n; ++i) {
    const Point p{surface.xyz[3 * i], surface.xyz[3 * i + 1], surface.xyz[3 * i + 2]};
    Voxel v;
    if (!quantizer.to_voxel(p, v)) {
      ++outside;
      continue;
    }
    const std::uint32_t base = options.surface_only ? v.z : base_row(quantizer, p, options.base);
    columns.push_back({encode(v.x, v.y, 0), std::min(v.z, base), std::max(v.z, base)});
  }
  Tree tree;
  if (options.surface_only) {
    // One voxel per point: the points bound the key list.
    std::vector<Key> keys;
    keys.reserve(columns.size());
    for (const Column& c : columns) keys.push_back(c.xy | encode(0, 0, c.low));
    tree = build_from_keys(std::move(keys), quantizer.depth());
  } else {
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
    std::uint64_t voxels = 0;
    for (const Column& c : columns) voxels += c.high - c.low + 1;
    if (voxels > options.max_voxels)
      throw InvalidArgument("terrain: the columns would hold " + std::to_string(voxels) + " voxels, more than " +
                            std::to_string(options.max_voxels) + "; ask for the surface only or a coarser grid");
    tree = columns.empty() ? build_from_sorted_keys({}, quantizer.depth()) : ColumnLevels(columns, quantizer.depth()).tree();
  }
  tree.set_frame(quantizer.frame());
  BuildReport::of(report, n, outside, tree);
  return tree;
}

}  // namespace vola::mesh
