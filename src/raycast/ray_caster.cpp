#include "vola/raycast/ray_caster.hpp"

#include <algorithm>
#include <bit>
#include <limits>

#include "vola/error.hpp"
#include "vola/parallel.hpp"

namespace vola::raycast {
namespace {

constexpr double kNever = std::numeric_limits<double>::infinity();

// The index of a moving axis just after time t: every plane crossed at a time <= t is
// behind it. `guess` comes from o + t*d and is corrected against the exact crossing
// times; the answer is known to lie in [lo, hi].
std::int64_t index_after(const RayAxes& axes, const Ray& ray, int a, double t, std::int64_t lo,
                         std::int64_t hi) noexcept {
  const double o = ray.origin[a];
  const double inv = axes.inverse[a];
  double g = o + t * ray.direction[a];
  g = axes.step[a] > 0 ? std::floor(g) : std::ceil(g) - 1.0;
  if (!(g >= static_cast<double>(lo))) g = static_cast<double>(lo);
  if (!(g <= static_cast<double>(hi))) g = static_cast<double>(hi);
  auto i = static_cast<std::int64_t>(g);
  // Crossing times grow along the axis's direction, so both loops stop at the answer.
  while (crossing_time(axes.exit_plane(a, i), o, inv) <= t) i += axes.step[a];
  while (crossing_time(axes.entry_plane(a, i), o, inv) > t) i -= axes.step[a];
  return i;
}

// The bit of cell c (cell indices of its level) in its block's word.
std::uint64_t cell_bit(const std::array<std::int32_t, 3>& c) noexcept {
  return std::uint64_t{1} << ((c[0] & 3) + 4 * (c[1] & 3) + 16 * (c[2] & 3));
}

// kBox.m[a][up][in][out]: the bits of a block's word whose cell index along axis a
// (0..3 inside the block) lies between the cell the ray enters and the last one it can
// reach, given as the number of planes between cells crossed at entry (in) and before
// leaving (out), for a ray moving up (up = 1) or down the axis. The three axes' masks
// ANDed together are the cells of the ray's bounding box inside the block.
// kBox.fixed[a][i]: the cells with index i along a (an axis the ray does not move on).
struct BoxMasks {
  std::uint64_t m[3][2][4][4];
  std::uint64_t fixed[3][4];
  std::uint64_t all[4][4];
};
constexpr BoxMasks make_box_masks() {
  BoxMasks r{};
  for (auto& row : r.all)
    for (auto& m : row) m = ~std::uint64_t{0};
  for (int a = 0; a < 3; ++a)
    for (unsigned b = 0; b < 64; ++b) {
      const int i = static_cast<int>(a == 0 ? b & 3 : a == 1 ? (b >> 2) & 3 : b >> 4);
      r.fixed[a][i] |= std::uint64_t{1} << b;
      for (int in = 0; in < 4; ++in)
        for (int out = in; out < 4; ++out) {
          if (i >= in && i <= out) r.m[a][1][in][out] |= std::uint64_t{1} << b;
          if (i >= 3 - out && i <= 3 - in) r.m[a][0][in][out] |= std::uint64_t{1} << b;
        }
    }
  return r;
}
constexpr BoxMasks kBox = make_box_masks();

// The per-axis constants of a direction whose signs are X, Y, Z (+1, -1, or 0 for an
// axis that does not move).
template <int X, int Y, int Z>
struct Octant {
  static constexpr std::array<int, 3> step{X, Y, Z};
  // 1 on an axis moving up: the plane through which it leaves cell c is c + 1.
  static constexpr std::array<std::int32_t, 3> ahead{X > 0, Y > 0, Z > 0};
  // Cell index inside a block -> planes crossed to reach it.
  static constexpr std::array<int, 3> flip{X > 0 ? 0 : 3, Y > 0 ? 0 : 3, Z > 0 ? 0 : 3};
  // The box masks per axis (all ones for an axis that does not move).
  static constexpr const std::uint64_t (&masks(int a))[4][4] { return step[a] ? kBox.m[a][step[a] > 0] : kBox.all; }
  // The cells of a block from cell index i on along axis a, in the ray's direction.
  static constexpr std::uint64_t onward(int a, std::int32_t i) { return masks(a)[(i & 3) ^ flip[a]][3]; }
  // A cell's bit in its block's word, moved one cell along axis a in the ray's direction.
  static constexpr std::uint64_t next_bit(int a, std::uint64_t bit) {
    const int stride = 1 << (2 * a);
    return step[a] > 0 ? bit << stride : bit >> stride;
  }
};

double min3(const std::array<double, 3>& x) noexcept { return std::min(x[0], std::min(x[1], x[2])); }

}  // namespace

RayCaster::RayCaster(const Tree& tree) : tree_(&tree) {
  // All levels in one array, level 0 first; first_child indexes this array.
  std::size_t total = 0;
  for (int l = 0; l < tree.depth(); ++l) total += tree.occupancy(l).size();
  nodes_.reserve(total);
  for (int l = 0; l < tree.depth(); ++l) {
    const auto words = tree.occupancy(l);
    std::uint64_t children = nodes_.size() + words.size();  // where the next level starts
    for (const std::uint64_t word : words) {
      nodes_.push_back(Node{word, children});
      children += static_cast<std::uint64_t>(std::popcount(word));
    }
  }
}

// The ray at one level, on the path from the root: its cell (in cells of that level),
// per axis the time it crosses the plane through which it leaves that cell, the cell's
// block, and the cells of that block the ray can still reach: the box from its cell to
// where it leaves the parent cell (the whole grid at the root), narrowed at every step.
// Cell indices are below 4^kMaxDepth = 2^20, so 32 bits hold them, and a step out of
// the grid too.
struct RayCaster::Level {
  std::array<std::int32_t, 3> cell;
  std::array<double, 3> leave;
  std::uint64_t bit;  // the cell's bit in the block's word, moved along with the cell
  std::uint64_t ahead;
  Node block;
};

std::optional<RayHit> RayCaster::cast(const Ray& ray) const {
  check_ray(ray);
  if (tree_->empty()) return std::nullopt;
  const RayAxes axes(ray);
  const auto side = static_cast<std::int64_t>(tree_->side());

  // Clip to the cube [0, side]^3: the first event that puts the ray inside it.
  std::array<std::int64_t, 3> v = axes.start;
  double t = 0.0;
  if (std::any_of(v.begin(), v.end(), [&](std::int64_t i) { return i < 0 || i >= side; })) {
    double enter = 0.0, exit = kNever;
    for (int a = 0; a < 3; ++a) {
      const int s = axes.step[a];
      if (s == 0) {
        if (v[a] < 0 || v[a] >= side) return std::nullopt;
        continue;
      }
      if ((v[a] < 0 && s < 0) || (v[a] >= side && s > 0)) return std::nullopt;
      const double o = ray.origin[a];
      if (v[a] < 0 || v[a] >= side)
        enter = std::max(enter, crossing_time(s > 0 ? 0.0 : static_cast<double>(side), o, axes.inverse[a]));
      exit = std::min(exit, crossing_time(s > 0 ? static_cast<double>(side) : 0.0, o, axes.inverse[a]));
    }
    if (!(enter < exit) || !(enter <= ray.t_max)) return std::nullopt;
    t = enter;
    for (int a = 0; a < 3; ++a)
      if (axes.step[a]) v[a] = index_after(axes, ray, a, t, 0, side - 1);
  }

  using Walk = std::optional<RayHit> (RayCaster::*)(const Ray&, const RayAxes&, const std::array<std::int64_t, 3>&,
                                                    double) const;
  // walks[9 * (x + 1) + 3 * (y + 1) + (z + 1)] for the signs x, y, z.
  static constexpr Walk walks[27] = {
      &RayCaster::walk<-1, -1, -1>, &RayCaster::walk<-1, -1, 0>, &RayCaster::walk<-1, -1, 1>,
      &RayCaster::walk<-1, 0, -1>,  &RayCaster::walk<-1, 0, 0>,  &RayCaster::walk<-1, 0, 1>,
      &RayCaster::walk<-1, 1, -1>,  &RayCaster::walk<-1, 1, 0>,  &RayCaster::walk<-1, 1, 1>,
      &RayCaster::walk<0, -1, -1>,  &RayCaster::walk<0, -1, 0>,  &RayCaster::walk<0, -1, 1>,
      &RayCaster::walk<0, 0, -1>,   &RayCaster::walk<0, 0, 0>,   &RayCaster::walk<0, 0, 1>,
      &RayCaster::walk<0, 1, -1>,   &RayCaster::walk<0, 1, 0>,   &RayCaster::walk<0, 1, 1>,
      &RayCaster::walk<1, -1, -1>,  &RayCaster::walk<1, -1, 0>,  &RayCaster::walk<1, -1, 1>,
      &RayCaster::walk<1, 0, -1>,   &RayCaster::walk<1, 0, 0>,   &RayCaster::walk<1, 0, 1>,
      &RayCaster::walk<1, 1, -1>,   &RayCaster::walk<1, 1, 0>,   &RayCaster::walk<1, 1, 1>,
  };
  const int octant = 9 * (axes.step[0] + 1) + 3 * (axes.step[1] + 1) + (axes.step[2] + 1);
  return (this->*walks[octant])(ray, axes, v, t);
}

namespace {

// The hit in voxel c at time t. Its normal: the lowest axis whose entry plane into the
// voxel is crossed now (none for a ray that starts inside it, `moved` false).
template <class S>
[[gnu::always_inline]] inline RayHit hit_in(const std::array<std::int32_t, 3>& c, double t, bool moved,
                                            const RayAxes& axes, const std::array<double, 3>& o,
                                            const std::array<double, 3>& inv) {
  RayHit hit;
  hit.voxel = Voxel{static_cast<std::uint32_t>(c[0]), static_cast<std::uint32_t>(c[1]), static_cast<std::uint32_t>(c[2])};
  hit.t = t;
  for (int a = 0; a < 3 && moved; ++a) {
    if (S::step[a] && crossing_time(axes.entry_plane(a, c[a]), o[a], inv[a]) == t) {
      hit.normal[a] = -S::step[a];
      break;
    }
  }
  return hit;
}

// Per axis, the child cells of `here` the ray is in from t until it leaves `here`
// (children `shift` bits below): the three planes between the children, in the order the
// ray crosses them, counted against t (the child it enters now, into `child`) and the
// time it leaves `here` (a bound on the last child). Returns the box of those children;
// ANDed with the child word it says whether the ray can hit anything below.
template <class S, class LevelT>
[[gnu::always_inline]] inline std::uint64_t enter_child(const LevelT& here, LevelT& child,
                                                        const std::array<std::int64_t, 3>& v,
                                                        const std::array<double, 3>& o,
                                                        const std::array<double, 3>& inv, double t, int shift) {
  const std::array<std::int32_t, 3>& c = here.cell;
  const double t_out = min3(here.leave);
  std::uint64_t box = ~std::uint64_t{0};
  for (int a = 0; a < 3; ++a) {
    if (!S::step[a]) {
      const auto rel = static_cast<std::int32_t>((v[a] >> shift) & 3);
      child.cell[a] = 4 * c[a] + rel;
      child.leave[a] = kNever;
      box &= kBox.fixed[a][rel];
      continue;
    }
    // The planes (in child cells) in crossing order: base + step * k for k = 1, 2, 3,
    // then at k = 4 the cell's own exit plane.
    const std::int32_t base = 4 * (c[a] + 1 - S::ahead[a]);
    const double t1 = crossing_time(static_cast<double>((base + S::step[a]) << shift), o[a], inv[a]);
    const double t2 = crossing_time(static_cast<double>((base + 2 * S::step[a]) << shift), o[a], inv[a]);
    const double t3 = crossing_time(static_cast<double>((base + 3 * S::step[a]) << shift), o[a], inv[a]);
    const int in = (t1 <= t) + (t2 <= t) + (t3 <= t);
    const int last_in = (t1 < t_out) + (t2 < t_out) + (t3 < t_out);
    // The child's exit plane: the next one after those crossed (k = 4 gives the same
    // double as the cell's own exit time).
    child.leave[a] = crossing_time(static_cast<double>((base + (in + 1) * S::step[a]) << shift), o[a], inv[a]);
    child.cell[a] = 4 * c[a] + (S::ahead[a] ? in : 3 - in);
    box &= S::masks(a)[in][last_in];
  }
  return box;
}

// From an empty cell (or one the ray cannot hit anything in), steps to the next cell of
// this level, every axis crossing now together, until a cell is occupied (true: descend
// or hit there) or the ray ends (false). An empty new cell is stepped over at once,
// unless nothing the ray can still reach in the block is occupied: then the parent cell
// is done too, and the step is on the parent's level. A step out of the parent block
// climbs to the coarsest level whose cell changed (its own parent's cell did not); the
// levels below it are entered again by descending.
template <class S, class LevelT, class ExitTime>
[[gnu::always_inline]] inline bool step_to_occupied(LevelT& here, LevelT* path, int& level, double& t, bool& moved,
                                                    double t_end, int last, ExitTime&& exit_time) {
  for (;;) {
    const double next = min3(here.leave);
    if (!(next <= t_end)) return false;
    const int shift = 2 * (last - level);
    std::uint32_t changed = 0;
    for (int a = 0; a < 3; ++a) {
      // Not crossing now (never on an axis that does not move). leave >= next, so > is
      // the same test as != but compiles to one compare and branch (no NaN check).
      if (here.leave[a] > next) continue;
      const std::int32_t i = here.cell[a] + S::step[a];
      changed |= static_cast<std::uint32_t>(i ^ here.cell[a]);
      here.cell[a] = i;
      here.leave[a] = exit_time(a, i, shift);
      here.bit = S::next_bit(a, here.bit);  // meaningless if the cell left the block: then it climbs
      here.ahead &= S::onward(a, i);
    }
    t = next;
    moved = true;
    // A cell index that left [0, 4^(level+1)) climbs past the root: the ray left the
    // grid. Indices that changed in their two low bits only stayed in the block.
    if (changed > 3) {
      const int up = static_cast<int>(std::bit_width(changed) - 1) / 2;
      if (up > level) return false;
      level -= up;
      const std::array<std::int32_t, 3> below = here.cell;
      here = path[level];
      for (int a = 0; a < 3; ++a) {
        const std::int32_t moved_to = below[a] >> (2 * up);
        if (moved_to == here.cell[a]) continue;
        here.cell[a] = moved_to;
        here.leave[a] = exit_time(a, moved_to, 2 * (last - level));
        here.bit = S::next_bit(a, here.bit);
        here.ahead &= S::onward(a, moved_to);
      }
    }
    if ((here.block.bits & here.bit) != 0) return true;
    if (here.block.bits & here.ahead) continue;  // empty, but not all the way: the next step
    if (level == 0) return false;
    --level;
    here = path[level];
  }
}

}  // namespace

template <int X, int Y, int Z>
std::optional<RayHit> RayCaster::walk(const Ray& ray, const RayAxes& axes, const std::array<std::int64_t, 3>& v,
                                      double t) const {
  using S = Octant<X, Y, Z>;
  const int last = tree_->depth() - 1;
  const std::array<double, 3> o = ray.origin;
  const std::array<double, 3> inv = axes.inverse;
  auto exit_time = [&](int a, std::int32_t c, int shift) {
    return crossing_time(static_cast<double>((c + S::ahead[a]) << shift), o[a], inv[a]);
  };
  // Events later than this end the ray (an infinite crossing time never happens).
  const double t_end = std::min(ray.t_max, std::numeric_limits<double>::max());

  // The levels above the current one, root first; the current one is kept apart from
  // them (`here`) so that the compiler can hold it in registers.
  std::array<Level, kMaxDepth> path;
  Level here;
  here.ahead = ~std::uint64_t{0};
  for (int a = 0; a < 3; ++a) {
    here.cell[a] = static_cast<std::int32_t>(v[a] >> (2 * last));
    here.leave[a] = S::step[a] ? exit_time(a, here.cell[a], 2 * last) : kNever;
    here.ahead &= S::step[a] ? S::onward(a, here.cell[a]) : kBox.fixed[a][here.cell[a]];
  }
  here.bit = cell_bit(here.cell);
  here.block = nodes_[0];
  // Has the ray crossed a plane yet (clipping counts)? The start voxel has no entry event.
  bool moved = t > 0.0;
  int level = 0;
  for (;;) {
    if ((here.block.bits & here.bit) != 0) {
      if (level == last) return hit_in<S>(here.cell, t, moved, axes, o, inv);
      // The child block; if the ray can reach none of its voxels, this cell is stepped
      // over like an empty one.
      const Node& child_block = nodes_[here.block.first_child + std::popcount(here.block.bits & (here.bit - 1))];
      Level child;
      const std::uint64_t box = enter_child<S>(here, child, v, o, inv, t, 2 * (last - level - 1));
      if (child_block.bits & box) {
        child.bit = cell_bit(child.cell);
        child.ahead = box;
        child.block = child_block;
        path[level] = here;
        here = child;
        ++level;
        continue;
      }
    }
    if (!step_to_occupied<S>(here, path.data(), level, t, moved, t_end, last, exit_time)) return std::nullopt;
  }
}

void RayCaster::cast(std::span<const Ray> rays, std::span<std::optional<RayHit>> hits, unsigned threads) const {
  if (hits.size() != rays.size()) throw InvalidArgument("cast: as many hits as rays are needed");
  for (const Ray& r : rays) check_ray(r);  // fail before any thread starts
  ParallelOptions parallel;
  parallel.threads = threads;
  parallel.grain = kRaysPerChunk;
  parallel.name = "raycast.cast";
  const auto cast_rays = [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) hits[i] = cast(rays[i]);
  };
  parallel_for(rays.size(), cast_rays, parallel);
}

}  // namespace vola::raycast
