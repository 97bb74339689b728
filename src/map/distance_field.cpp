#include "vola/map/distance_field.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <string>

#include "vola/error.hpp"
#include "vola/map/state_map.hpp"

namespace vola::map {

namespace {

using Cell = std::array<std::int64_t, 3>;

constexpr double kFar = 1e20;  // "no obstacle": finite, so the parabola algebra stays exact

std::uint64_t cells_of(const GridBox& b) {
  std::uint64_t n = 1;
  for (int a = 0; a < 3; ++a) n *= static_cast<std::uint64_t>(std::max<std::int64_t>(0, b.hi[a] - b.lo[a]));
  return n;
}

// Not clipped to the grid: the cells just outside it lie near the obstacles on its faces
// (a field clipped to the grid read max_distance a voxel below a map's lowest obstacle).
GridBox grown(const GridBox& b, std::int64_t margin) {
  GridBox g;
  for (int a = 0; a < 3; ++a) {
    g.lo[a] = b.lo[a] - margin;
    g.hi[a] = b.hi[a] + margin;
  }
  return g;
}

GridBox clipped(const GridBox& b, const GridBox& to) {
  GridBox c;
  for (int a = 0; a < 3; ++a) {
    c.lo[a] = std::max(b.lo[a], to.lo[a]);
    c.hi[a] = std::min(b.hi[a], to.hi[a]);
  }
  return c;
}

// Felzenszwalb and Huttenlocher's 1D squared distance transform of n samples at `stride`:
// out[i] = min_q (i - q)^2 + f[q], by the lower envelope of the parabolas.
void transform_line(double* f, std::size_t n, std::size_t stride, std::vector<double>& scratch,
                    std::vector<std::int64_t>& v, std::vector<double>& z) {
  scratch.resize(n);
  v.resize(n);
  z.resize(n + 1);
  for (std::size_t i = 0; i < n; ++i) scratch[i] = f[i * stride];
  std::size_t k = 0;
  v[0] = 0;
  z[0] = -std::numeric_limits<double>::infinity();
  z[1] = std::numeric_limits<double>::infinity();
  for (std::size_t q = 1; q < n; ++q) {
    const double fq = scratch[q] + static_cast<double>(q) * static_cast<double>(q);
    // Where parabola q meets the envelope's last one; z[0] = -inf ends the walk back.
    const auto meet = [&] {
      const auto p = static_cast<double>(v[k]);
      return (fq - (scratch[static_cast<std::size_t>(v[k])] + p * p)) / (2.0 * static_cast<double>(q) - 2.0 * p);
    };
    double s = meet();
    while (s <= z[k]) {
      --k;
      s = meet();
    }
    ++k;
    v[k] = static_cast<std::int64_t>(q);
    z[k] = s;
    z[k + 1] = std::numeric_limits<double>::infinity();
  }
  k = 0;
  for (std::size_t i = 0; i < n; ++i) {
    while (z[k + 1] < static_cast<double>(i)) ++k;
    const double d = static_cast<double>(i) - static_cast<double>(v[k]);
    f[i * stride] = d * d + scratch[static_cast<std::size_t>(v[k])];
  }
}

}  // namespace

DistanceField::DistanceField(const Tree& tree, const GridBox& box, double max_distance)
    : frame_(tree.frame()), max_distance_(max_distance), side_(tree.side()) {
  if (!(max_distance > 0.0) || !std::isfinite(max_distance))
    throw InvalidArgument("max_distance must be finite and > 0");
  max_voxels_ = max_distance / frame_.voxel_size;
  margin_ = static_cast<std::int64_t>(std::ceil(max_voxels_));
  // Beyond max_distance around the grid every cell is max_distance: no need to store it.
  const std::int64_t side = side_;
  box_ = clipped(box, GridBox{{-margin_, -margin_, -margin_}, {side + margin_, side + margin_, side + margin_}});
  const std::uint64_t cells = cells_of(box_);
  if (cells == 0) throw InvalidArgument("the distance field's box holds no voxel within max_distance of the grid");
  if (cells > kMaxCells || cells_of(grown(box_, margin_)) > 2 * kMaxCells)
    throw InvalidArgument("a distance field of " + std::to_string(cells) + " cells is more than " +
                          std::to_string(kMaxCells) + ": give a smaller box");
  values_.assign(cells, static_cast<float>(max_voxels_));
  compute(tree, box_);
}

namespace {

GridBox voxel_bounds(const Tree& tree, double max_distance) {
  GridBox b{{tree.side(), tree.side(), tree.side()}, {0, 0, 0}};
  tree.for_each_voxel([&](const Voxel& v) {
    const Cell c{v.x, v.y, v.z};
    for (int a = 0; a < 3; ++a) {
      b.lo[a] = std::min(b.lo[a], c[a]);
      b.hi[a] = std::max(b.hi[a], c[a] + 1);
    }
  });
  if (tree.voxel_count() == 0) b = GridBox{};
  const auto margin = static_cast<std::int64_t>(std::ceil(max_distance / tree.frame().voxel_size));
  return grown(b, margin);
}

}  // namespace

DistanceField::DistanceField(const Tree& tree, double max_distance)
    : DistanceField(tree, voxel_bounds(tree, max_distance > 0.0 ? max_distance : 1.0), max_distance) {}

void DistanceField::update(const Tree& tree, const GridBox& changed) {
  if (tree.side() != side_ || !(tree.frame() == frame_))
    throw InvalidArgument("update: the tree is on another grid than the distance field");
  const GridBox region = clipped(grown(changed, margin_), box_);
  if (cells_of(region) > 0) compute(tree, region);
}

void DistanceField::compute(const Tree& tree, const GridBox& region) {
  std::optional<Tree> occupied;
  if (is_state_map(tree)) occupied = occupied_tree(tree);
  const Tree& obstacles = occupied ? *occupied : tree;
  const GridBox g = grown(region, margin_);
  const std::array<std::size_t, 3> n{static_cast<std::size_t>(g.hi[0] - g.lo[0]),
                                     static_cast<std::size_t>(g.hi[1] - g.lo[1]),
                                     static_cast<std::size_t>(g.hi[2] - g.lo[2])};
  std::vector<double> f(n[0] * n[1] * n[2], kFar);
  const auto at = [&](std::int64_t x, std::int64_t y, std::int64_t z) {
    return (static_cast<std::size_t>(z - g.lo[2]) * n[1] + static_cast<std::size_t>(y - g.lo[1])) * n[0] +
           static_cast<std::size_t>(x - g.lo[0]);
  };
  // The obstacles in the grown box: by their list when there are fewer than cells.
  if (obstacles.voxel_count() < f.size()) {
    obstacles.for_each_voxel([&](const Voxel& v) {
      const Cell c{v.x, v.y, v.z};
      for (int a = 0; a < 3; ++a)
        if (c[a] < g.lo[a] || c[a] >= g.hi[a]) return;
      f[at(c[0], c[1], c[2])] = 0.0;
    });
  } else {
    const GridBox in_grid = clipped(g, GridBox{{0, 0, 0}, {side_, side_, side_}});  // obstacles lie on the grid
    for (std::int64_t z = in_grid.lo[2]; z < in_grid.hi[2]; ++z)
      for (std::int64_t y = in_grid.lo[1]; y < in_grid.hi[1]; ++y)
        for (std::int64_t x = in_grid.lo[0]; x < in_grid.hi[0]; ++x)
          if (obstacles.contains(static_cast<std::uint32_t>(x), static_cast<std::uint32_t>(y),
                                 static_cast<std::uint32_t>(z)))
            f[at(x, y, z)] = 0.0;
  }
  std::vector<double> scratch, z;
  std::vector<std::int64_t> v;
  for (std::size_t k = 0; k < n[2]; ++k)
    for (std::size_t j = 0; j < n[1]; ++j) transform_line(&f[(k * n[1] + j) * n[0]], n[0], 1, scratch, v, z);
  for (std::size_t k = 0; k < n[2]; ++k)
    for (std::size_t i = 0; i < n[0]; ++i) transform_line(&f[k * n[1] * n[0] + i], n[1], n[0], scratch, v, z);
  for (std::size_t j = 0; j < n[1]; ++j)
    for (std::size_t i = 0; i < n[0]; ++i) transform_line(&f[j * n[0] + i], n[2], n[0] * n[1], scratch, v, z);
  for (std::int64_t zc = region.lo[2]; zc < region.hi[2]; ++zc)
    for (std::int64_t y = region.lo[1]; y < region.hi[1]; ++y)
      for (std::int64_t x = region.lo[0]; x < region.hi[0]; ++x)
        values_[index({x, y, zc})] = static_cast<float>(std::min(std::sqrt(f[at(x, y, zc)]), max_voxels_));
}

bool DistanceField::inside(const Cell& v) const noexcept {
  for (int a = 0; a < 3; ++a)
    if (v[a] < box_.lo[a] || v[a] >= box_.hi[a]) return false;
  return true;
}

std::size_t DistanceField::index(const Cell& v) const noexcept {
  const auto nx = static_cast<std::size_t>(box_.hi[0] - box_.lo[0]);
  const auto ny = static_cast<std::size_t>(box_.hi[1] - box_.lo[1]);
  return (static_cast<std::size_t>(v[2] - box_.lo[2]) * ny + static_cast<std::size_t>(v[1] - box_.lo[1])) * nx +
         static_cast<std::size_t>(v[0] - box_.lo[0]);
}

Cell DistanceField::voxel_of(const Point& world) const noexcept {
  Cell c{};
  for (int a = 0; a < 3; ++a) {
    const double g = (world[a] - frame_.origin[a]) / frame_.voxel_size;
    // Also maps NaN far outside (the comparison fails): never inside the box.
    c[a] = std::abs(g) < 4.0e9 ? static_cast<std::int64_t>(std::floor(g)) : std::numeric_limits<std::int64_t>::min();
  }
  return c;
}

float DistanceField::voxels_at(const Cell& v) const noexcept {
  return inside(v) ? values_[index(v)] : static_cast<float>(max_voxels_);
}

double DistanceField::distance(const Point& world) const noexcept {
  return static_cast<double>(voxels_at(voxel_of(world))) * frame_.voxel_size;
}

Point DistanceField::gradient(const Point& world) const noexcept {
  const Cell c = voxel_of(world);
  Point g{0, 0, 0};
  if (!inside(c)) return g;
  for (int a = 0; a < 3; ++a) {
    Cell up = c, down = c;
    ++up[a];
    --down[a];
    const bool has_up = inside(up), has_down = inside(down);
    if (has_up && has_down) g[a] = (voxels_at(up) - voxels_at(down)) / 2.0;
    else if (has_up) g[a] = voxels_at(up) - voxels_at(c);
    else if (has_down) g[a] = voxels_at(c) - voxels_at(down);
  }
  return g;
}

}  // namespace vola::map
