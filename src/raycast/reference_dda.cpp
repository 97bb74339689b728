#include "vola/raycast/reference_dda.hpp"

#include <algorithm>

namespace vola::raycast {

std::optional<RayHit> reference_cast(const Tree& tree, const Ray& ray) {
  check_ray(ray);
  const RayAxes axes(ray);
  const auto side = static_cast<std::int64_t>(tree.side());
  constexpr double kNever = std::numeric_limits<double>::infinity();

  std::array<std::int64_t, 3> v = axes.start;
  std::array<double, 3> next{};  // crossing time of each axis's next plane
  for (int a = 0; a < 3; ++a)
    next[a] = axes.step[a] ? crossing_time(axes.exit_plane(a, v[a]), ray.origin[a], axes.inverse[a]) : kNever;

  RayHit hit;
  for (;;) {
    bool inside = true;
    for (int a = 0; a < 3; ++a) {
      if (v[a] < 0 || v[a] >= side) inside = false;
      // Outside on an axis and not moving towards the grid: it never comes back.
      if ((v[a] < 0 && axes.step[a] <= 0) || (v[a] >= side && axes.step[a] >= 0)) return std::nullopt;
    }
    if (inside) {
      const Voxel voxel{static_cast<std::uint32_t>(v[0]), static_cast<std::uint32_t>(v[1]),
                        static_cast<std::uint32_t>(v[2])};
      if (tree.contains(voxel)) {
        hit.voxel = voxel;
        return hit;
      }
    }
    const double t = std::min({next[0], next[1], next[2]});
    if (t == kNever || !(t <= ray.t_max)) return std::nullopt;
    hit.t = t;
    hit.normal = {0, 0, 0};
    bool first = true;
    for (int a = 0; a < 3; ++a) {
      if (next[a] != t) continue;
      v[a] += axes.step[a];
      next[a] = crossing_time(axes.exit_plane(a, v[a]), ray.origin[a], axes.inverse[a]);
      if (first) hit.normal[a] = -axes.step[a];
      first = false;
    }
  }
}

}  // namespace vola::raycast
