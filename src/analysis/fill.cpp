// Scanline flood fill of the outside inside the bounding box grown by one cell: a seed
// grows into its whole run along x, then one seed per run is pushed for the four
// neighbouring rows. The stack holds runs, not cells.
#include <algorithm>
#include <string>
#include <vector>

#include "same_frame.hpp"
#include "vola/analysis/fill.hpp"
#include "vola/builder.hpp"
#include "vola/error.hpp"

namespace vola::analysis {

namespace {

class BitGrid {
 public:
  BitGrid(std::int64_t nx, std::int64_t ny, std::int64_t nz)
      : nx_(nx), ny_(ny), bits_(static_cast<std::size_t>((nx * ny * nz + 63) / 64), 0) {}
  std::uint64_t index(std::int64_t x, std::int64_t y, std::int64_t z) const noexcept {
    return static_cast<std::uint64_t>((z * ny_ + y) * nx_ + x);
  }
  bool get(std::uint64_t i) const noexcept { return (bits_[i >> 6] >> (i & 63)) & 1u; }
  void set(std::uint64_t i) noexcept { bits_[i >> 6] |= std::uint64_t{1} << (i & 63); }

 private:
  std::int64_t nx_, ny_;
  std::vector<std::uint64_t> bits_;
};

struct Seed {
  std::int64_t x, y, z;
};

}  // namespace

Tree fill_cavities(const Tree& tree, FillReport* report) {
  if (report) *report = {};
  if (tree.empty()) return detail::with_frame_of(build_from_sorted_keys({}, tree.depth()), tree);
  std::int64_t lo[3] = {INT64_MAX, INT64_MAX, INT64_MAX}, hi[3] = {-1, -1, -1};
  tree.for_each_voxel([&](const Voxel& v) {
    const std::int64_t c[3] = {v.x, v.y, v.z};
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::min(lo[a], c[a]);
      hi[a] = std::max(hi[a], c[a]);
    }
  });
  // Local box: one empty cell of margin per side, so the outside surrounds the voxels.
  const std::int64_t nx = hi[0] - lo[0] + 3, ny = hi[1] - lo[1] + 3, nz = hi[2] - lo[2] + 3;
  const double cells = static_cast<double>(nx) * static_cast<double>(ny) * static_cast<double>(nz);
  if (cells > static_cast<double>(kMaxFillCells))
    throw InvalidArgument("fill: the voxels' bounding box (" + std::to_string(nx - 2) + " x " + std::to_string(ny - 2) +
                          " x " + std::to_string(nz - 2) + ") is beyond the " + std::to_string(kMaxFillCells) +
                          "-cell limit; crop first");
  BitGrid solid(nx, ny, nz), outside(nx, ny, nz);
  tree.for_each_voxel([&](const Voxel& v) { solid.set(solid.index(v.x - lo[0] + 1, v.y - lo[1] + 1, v.z - lo[2] + 1)); });

  auto open = [&](std::int64_t x, std::int64_t y, std::int64_t z) {
    const std::uint64_t i = solid.index(x, y, z);
    return !solid.get(i) && !outside.get(i);
  };
  std::vector<Seed> stack{{0, 0, 0}};
  while (!stack.empty()) {
    const Seed s = stack.back();
    stack.pop_back();
    if (!open(s.x, s.y, s.z)) continue;
    std::int64_t x0 = s.x, x1 = s.x;
    while (x0 > 0 && open(x0 - 1, s.y, s.z)) --x0;
    while (x1 + 1 < nx && open(x1 + 1, s.y, s.z)) ++x1;
    for (std::int64_t x = x0; x <= x1; ++x) outside.set(outside.index(x, s.y, s.z));
    const Seed rows[4] = {{0, s.y - 1, s.z}, {0, s.y + 1, s.z}, {0, s.y, s.z - 1}, {0, s.y, s.z + 1}};
    for (const Seed& row : rows) {
      if (row.y < 0 || row.y >= ny || row.z < 0 || row.z >= nz) continue;
      bool in_run = false;
      for (std::int64_t x = x0; x <= x1; ++x) {
        const bool o = open(x, row.y, row.z);
        if (o && !in_run) stack.push_back({x, row.y, row.z});
        in_run = o;
      }
    }
  }

  std::vector<Key> keys = tree.keys();
  const std::size_t before = keys.size();
  for (std::int64_t z = 1; z + 1 < nz; ++z)
    for (std::int64_t y = 1; y + 1 < ny; ++y)
      for (std::int64_t x = 1; x + 1 < nx; ++x) {
        const std::uint64_t i = solid.index(x, y, z);
        if (!solid.get(i) && !outside.get(i))
          keys.push_back(encode(static_cast<std::uint32_t>(x - 1 + lo[0]), static_cast<std::uint32_t>(y - 1 + lo[1]),
                                static_cast<std::uint32_t>(z - 1 + lo[2])));
      }
  if (report) report->filled = keys.size() - before;
  return detail::with_frame_of(build_from_keys(std::move(keys), tree.depth()), tree);
}

}  // namespace vola::analysis
