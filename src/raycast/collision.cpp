#include "vola/raycast/collision.hpp"

#include <bit>
#include <cmath>

#include "vola/error.hpp"

namespace vola::raycast {

Collider::Collider(const Tree& tree) : caster_(tree) {
  for (int l = 0; l < tree.depth(); ++l) rank_.emplace_back(tree.occupancy(l));
}

// Visits the occupied cells of the block (cells from `origin` on the level's grid) whose
// cube [lo, hi] passes `overlaps`, down to the voxels; true at the first voxel that does.
template <class Overlaps>
bool Collider::any_voxel(int level, std::size_t block, const Voxel& origin, const Overlaps& overlaps) const {
  const Tree& tree = caster_.tree();
  const auto words = tree.occupancy(level);
  const std::uint64_t word = words[block];
  const double size = std::ldexp(1.0, 2 * (tree.depth() - 1 - level));
  for (std::uint64_t rest = word; rest; rest &= rest - 1) {
    const auto b = static_cast<unsigned>(std::countr_zero(rest));
    const Voxel cell{origin.x + (b & 3u), origin.y + ((b >> 2) & 3u), origin.z + (b >> 4)};
    const Point lo{cell.x * size, cell.y * size, cell.z * size};
    const Point hi{lo[0] + size, lo[1] + size, lo[2] + size};
    if (!overlaps(lo, hi)) continue;
    if (level == tree.depth() - 1) return true;
    const std::size_t child = rank_[level].before(words, block) +
                              static_cast<std::size_t>(std::popcount(word & ((std::uint64_t{1} << b) - 1)));
    if (any_voxel(level + 1, child, Voxel{cell.x * 4, cell.y * 4, cell.z * 4}, overlaps)) return true;
  }
  return false;
}

std::optional<RayHit> Collider::segment(const Point& a, const Point& b) const {
  const Point d{b[0] - a[0], b[1] - a[1], b[2] - a[2]};
  if (d == Point{0, 0, 0}) {
    // A segment of no length (a robot standing still between two waypoints) is its point:
    // a hit at t = 0 when the point lies in an occupied voxel (the one whose cube holds it,
    // as a ray starting there would enter it).
    check_ray(Ray{a, Point{1, 0, 0}, 0.0});  // the point's bounds, as a ray origin's
    if (!(a[0] >= 0 && a[1] >= 0 && a[2] >= 0)) return std::nullopt;
    const double side = static_cast<double>(tree().side());
    if (!(a[0] < side && a[1] < side && a[2] < side)) return std::nullopt;
    const Voxel v{static_cast<std::uint32_t>(a[0]), static_cast<std::uint32_t>(a[1]), static_cast<std::uint32_t>(a[2])};
    if (!tree().contains(v.x, v.y, v.z)) return std::nullopt;
    return RayHit{v, 0.0, {0, 0, 0}};
  }
  return caster_.cast(Ray{a, d, 1.0});
}

bool Collider::sphere(const Point& centre, double radius) const {
  // Bounded as ray origins are, so that the squared distances below cannot overflow (a
  // centre and radius of 1e308 both squared to infinity and "hit").
  for (const double c : centre)
    if (!std::isfinite(c) || std::abs(c) > kMaxOriginMagnitude)
      throw InvalidArgument("sphere: the centre must be finite and within 1e12 voxels of the grid");
  if (!(radius >= 0.0) || !std::isfinite(radius)) throw InvalidArgument("sphere: the radius must be finite and >= 0");
  if (tree().empty()) return false;
  if (radius > 4 * kMaxOriginMagnitude) return true;  // reaches every cell of any grid from any such centre
  const double r2 = radius * radius;
  return any_voxel(0, 0, Voxel{}, [&](const Point& lo, const Point& hi) {
    double d2 = 0.0;
    for (int a = 0; a < 3; ++a) {
      const double gap = centre[a] < lo[a] ? lo[a] - centre[a] : centre[a] > hi[a] ? centre[a] - hi[a] : 0.0;
      d2 += gap * gap;
    }
    return d2 <= r2;
  });
}

bool Collider::box(const Box& box) const {
  for (int a = 0; a < 3; ++a)
    if (!std::isfinite(box.min[a]) || !std::isfinite(box.max[a]) || box.min[a] > box.max[a])
      throw InvalidArgument("box: min and max must be finite with min <= max");
  if (tree().empty()) return false;
  return any_voxel(0, 0, Voxel{}, [&](const Point& lo, const Point& hi) {
    for (int a = 0; a < 3; ++a)
      if (!(box.min[a] < hi[a] && box.max[a] > lo[a])) return false;
    return true;
  });
}

}  // namespace vola::raycast
