#include "vola/learn/occupancy.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "vola/error.hpp"

namespace vola::learn {

void fill_occupancy(const Tree& tree, int out_side, double angle_radians, std::span<float> out) {
  const std::uint64_t side = tree.side();
  if (out_side <= 0 || std::uint64_t(out_side) > side)
    throw InvalidArgument("input side " + std::to_string(out_side) + " must be 1.." + std::to_string(side));
  const std::size_t cells = std::size_t(out_side) * out_side * out_side;
  if (out.size() != cells) throw InvalidArgument("input buffer holds " + std::to_string(out.size()) + " floats, not " + std::to_string(out_side) + "^3");
  std::fill(out.begin(), out.end(), 0.0f);
  const std::uint64_t s = std::uint64_t(out_side);
  const auto set = [&](std::uint64_t x, std::uint64_t y, std::uint64_t z) {
    out[((x * s / side) * s + y * s / side) * s + z * s / side] = 1.0f;
  };
  if (angle_radians == 0) {
    tree.for_each_voxel([&](const Voxel& v) { set(v.x, v.y, v.z); });
    return;
  }
  const double c = std::cos(angle_radians), sn = std::sin(angle_radians);
  const double centre = static_cast<double>(side) / 2;
  const double limit = static_cast<double>(side);
  tree.for_each_voxel([&](const Voxel& v) {
    const double px = v.x + 0.5 - centre, py = v.y + 0.5 - centre;
    const double x = c * px - sn * py + centre, y = sn * px + c * py + centre;
    if (x >= 0 && y >= 0 && x < limit && y < limit) set(std::uint64_t(x), std::uint64_t(y), v.z);
  });
}

}  // namespace vola::learn
