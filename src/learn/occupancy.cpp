#include "vola/learn/occupancy.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "vola/builder.hpp"
#include "vola/error.hpp"

namespace vola::learn {

namespace {

// The whole number of quarter turns `angle` is (0..3), or -1 when it is none.
int quarter_turns_of(double angle) {
  const double quarters = angle / (std::numbers::pi / 2);
  const double nearest = std::round(quarters);
  if (std::abs(angle - nearest * (std::numbers::pi / 2)) > 1e-9) return -1;
  return static_cast<int>(((static_cast<long long>(nearest) % 4) + 4) % 4);
}

// (x, y) turned by `quarters` quarter turns about the centre of a side-N grid.
void turn_exact(std::uint64_t& x, std::uint64_t& y, int quarters, std::uint64_t side) {
  for (int q = 0; q < quarters; ++q) {
    const std::uint64_t nx = side - 1 - y;
    y = x;
    x = nx;
  }
}

void check_out(const Tree& tree, int out_side, std::span<float> out) {
  const std::uint64_t side = tree.side();
  if (out_side <= 0 || std::uint64_t(out_side) > side)
    throw InvalidArgument("input side " + std::to_string(out_side) + " must be 1.." + std::to_string(side));
  const std::size_t cells = std::size_t(out_side) * out_side * out_side;
  if (out.size() != cells)
    throw InvalidArgument("input buffer holds " + std::to_string(out.size()) + " floats, not " + std::to_string(out_side) + "^3");
}

}  // namespace

void fill_occupancy(const Tree& tree, int out_side, double angle_radians, std::span<float> out) {
  Placement placement;
  placement.angle_radians = angle_radians;
  fill_occupancy(tree, out_side, placement, out);
}

void fill_occupancy(const Tree& tree, int out_side, const Placement& placement, std::span<float> out) {
  check_out(tree, out_side, out);
  std::fill(out.begin(), out.end(), 0.0f);
  const std::uint64_t side = tree.side();
  const std::uint64_t s = std::uint64_t(out_side);
  const auto set = [&](std::uint64_t x, std::uint64_t y, std::uint64_t z) {
    out[((x * s / side) * s + y * s / side) * s + z * s / side] = 1.0f;
  };
  const bool moved = placement.scale != 1 || placement.shift[0] != 0 || placement.shift[1] != 0 || placement.shift[2] != 0;
  const int quarters = quarter_turns_of(placement.angle_radians);
  if (!moved && quarters >= 0) {
    tree.for_each_voxel([&](const Voxel& v) {
      std::uint64_t x = v.x, y = v.y;
      turn_exact(x, y, quarters, side);
      set(x, y, v.z);
    });
    return;
  }
  const double c = std::cos(placement.angle_radians), sn = std::sin(placement.angle_radians);
  const double centre = static_cast<double>(side) / 2;
  const double limit = static_cast<double>(side);
  const double k = placement.scale;
  tree.for_each_voxel([&](const Voxel& v) {
    const double px = v.x + 0.5 - centre, py = v.y + 0.5 - centre;
    double x = c * px - sn * py, y = sn * px + c * py, z = v.z + 0.5 - centre;
    if (moved) {
      x = k * x + placement.shift[0];
      y = k * y + placement.shift[1];
      z = k * z + placement.shift[2];
    }
    x += centre;
    y += centre;
    z = moved ? z + centre : double(v.z);
    if (x >= 0 && y >= 0 && z >= 0 && x < limit && y < limit && z < limit)
      set(std::uint64_t(x), std::uint64_t(y), std::uint64_t(z));
  });
}

void keep_surface(std::span<float> cells, int side) {
  const std::size_t n = static_cast<std::size_t>(side);
  if (cells.size() != n * n * n)
    throw InvalidArgument("keep_surface: " + std::to_string(cells.size()) + " cells are not a grid of side " +
                          std::to_string(side));
  const std::vector<float> solid(cells.begin(), cells.end());
  auto filled = [&](std::size_t x, std::size_t y, std::size_t z) { return solid[(z * n + y) * n + x] > 0.0f; };
  for (std::size_t z = 1; z + 1 < n; ++z)
    for (std::size_t y = 1; y + 1 < n; ++y)
      for (std::size_t x = 1; x + 1 < n; ++x)
        if (filled(x, y, z) && filled(x - 1, y, z) && filled(x + 1, y, z) && filled(x, y - 1, z) &&
            filled(x, y + 1, z) && filled(x, y, z - 1) && filled(x, y, z + 1))
          cells[(z * n + y) * n + x] = 0.0f;
}

Tree turn_quarters(const Tree& tree, int quarter_turns) {
  const int quarters = ((quarter_turns % 4) + 4) % 4;
  std::vector<Voxel> voxels;
  tree.for_each_voxel([&](const Voxel& v) {
    std::uint64_t x = v.x, y = v.y;
    turn_exact(x, y, quarters, tree.side());
    voxels.push_back({std::uint32_t(x), std::uint32_t(y), v.z});
  });
  return build_from_voxels(voxels, tree.depth());
}

}  // namespace vola::learn
