#include "vola/raycast/ray_caster.hpp"

#include <algorithm>
#include <atomic>
#include <bit>
#include <thread>

#include "vola/error.hpp"

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
unsigned cell_bit(const std::array<std::int64_t, 3>& c) noexcept {
  return static_cast<unsigned>((c[0] & 3) + 4 * (c[1] & 3) + 16 * (c[2] & 3));
}

}  // namespace

RayCaster::RayCaster(const Tree& tree) : tree_(&tree) {
  nodes_.resize(static_cast<std::size_t>(tree.depth()));
  for (int l = 0; l < tree.depth(); ++l) {
    const auto words = tree.occupancy(l);
    auto& nodes = nodes_[static_cast<std::size_t>(l)];
    nodes.resize(words.size());
    std::uint64_t children = 0;
    for (std::size_t i = 0; i < words.size(); ++i) {
      nodes[i] = Node{words[i], children};
      children += static_cast<std::uint64_t>(std::popcount(words[i]));
    }
  }
}

std::optional<RayHit> RayCaster::cast(const Ray& ray) const {
  check_ray(ray);
  if (tree_->empty()) return std::nullopt;
  const RayAxes axes(ray);
  const int last = tree_->depth() - 1;
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

  // Per level: the ray's cell (in cells of that level) and, per axis, the time it
  // crosses the plane through which it leaves that cell. Stepping a cell costs one
  // multiplication per axis that moves; the voxel-level index inside a cell is worked
  // out only when descending into it.
  std::array<std::array<std::int64_t, 3>, kMaxDepth> cell{};
  std::array<std::array<double, 3>, kMaxDepth> leave{};
  std::array<std::size_t, kMaxDepth> block{};  // the cell's block on each level of the path
  auto exit_time = [&](int a, std::int64_t c, int shift) {
    return crossing_time(static_cast<double>((axes.step[a] > 0 ? c + 1 : c) << shift), ray.origin[a], axes.inverse[a]);
  };
  auto enter_level = [&](int level, const std::array<std::int64_t, 3>& voxel) {
    const int shift = 2 * (last - level);
    for (int a = 0; a < 3; ++a) {
      cell[level][a] = voxel[a] >> shift;
      leave[level][a] = axes.step[a] ? exit_time(a, cell[level][a], shift) : kNever;
    }
  };
  // Has the ray crossed a plane yet (clipping counts)? The start voxel has no entry event.
  bool moved = t > 0.0;
  int level = 0;
  enter_level(0, v);
  for (;;) {
    const std::array<std::int64_t, 3>& c = cell[level];
    const unsigned bit = cell_bit(c);
    const Node& node = nodes_[static_cast<std::size_t>(level)][block[level]];
    if ((node.bits >> bit) & 1u) {
      if (level == last) {
        RayHit hit;
        hit.voxel = Voxel{static_cast<std::uint32_t>(c[0]), static_cast<std::uint32_t>(c[1]),
                          static_cast<std::uint32_t>(c[2])};
        hit.t = t;
        // The normal: the lowest axis whose entry plane into the voxel is crossed now.
        for (int a = 0; a < 3 && moved; ++a) {
          if (axes.step[a] && crossing_time(axes.entry_plane(a, c[a]), ray.origin[a], axes.inverse[a]) == t) {
            hit.normal[a] = -axes.step[a];
            break;
          }
        }
        return hit;
      }
      // Descend: the child cell holding the voxel the ray is in just after t.
      block[level + 1] = node.first_child + static_cast<std::size_t>(std::popcount(node.bits & ((std::uint64_t{1} << bit) - 1)));
      const int shift = 2 * (last - level);
      for (int a = 0; a < 3; ++a) {
        if (!axes.step[a]) continue;
        const std::int64_t lo = c[a] << shift;
        v[a] = index_after(axes, ray, a, t, lo, lo + (std::int64_t{1} << shift) - 1);
      }
      enter_level(++level, v);
      continue;
    }

    // An empty cell: step to the next cell of this level, every axis crossing now together.
    std::array<double, 3>& out = leave[level];
    const double next = std::min({out[0], out[1], out[2]});
    if (next == kNever || !(next <= ray.t_max)) return std::nullopt;
    const int shift = 2 * (last - level);
    const std::int64_t cells = side >> shift;
    std::int64_t changed = 0;
    std::array<std::int64_t, 3>& here = cell[level];
    for (int a = 0; a < 3; ++a) {
      if (out[a] != next) continue;
      const std::int64_t i = here[a] + axes.step[a];
      if (i < 0 || i >= cells) return std::nullopt;
      changed |= i ^ here[a];
      here[a] = i;
      out[a] = exit_time(a, i, shift);
    }
    t = next;
    moved = true;
    // Left the parent block: climb to the coarsest level whose cell changed (its own
    // parent's cell did not); the levels below it are entered again by descending.
    const int up = static_cast<int>(std::bit_width(static_cast<std::uint64_t>(changed)) - 1) / 2;
    if (up > 0) {
      level -= up;
      for (int a = 0; a < 3; ++a) {
        const std::int64_t moved_to = here[a] >> (2 * up);
        if (moved_to == cell[level][a]) continue;
        cell[level][a] = moved_to;
        leave[level][a] = exit_time(a, moved_to, 2 * (last - level));
      }
    }
  }
}

void parallel_chunks(std::size_t count, unsigned threads,
                     const std::function<void(std::size_t, std::size_t)>& f) {
  if (threads == 0) threads = std::max(1u, std::thread::hardware_concurrency());
  constexpr std::size_t kChunk = 256;
  const std::size_t chunks = (count + kChunk - 1) / kChunk;
  threads = static_cast<unsigned>(std::min<std::size_t>(threads, std::max<std::size_t>(chunks, 1)));
  std::atomic<std::size_t> next{0};
  auto work = [&] {
    for (std::size_t c; (c = next.fetch_add(1)) < chunks;) f(c * kChunk, std::min(count, (c + 1) * kChunk));
  };
  if (threads <= 1) {
    work();
    return;
  }
  std::vector<std::jthread> pool;
  pool.reserve(threads - 1);
  for (unsigned i = 1; i < threads; ++i) pool.emplace_back(work);
  work();
}

void RayCaster::cast(std::span<const Ray> rays, std::span<std::optional<RayHit>> hits, unsigned threads) const {
  if (hits.size() != rays.size()) throw InvalidArgument("cast: as many hits as rays are needed");
  for (const Ray& r : rays) check_ray(r);  // fail before any thread starts
  parallel_chunks(rays.size(), threads, [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) hits[i] = cast(rays[i]);
  });
}

}  // namespace vola::raycast
