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

}  // namespace

RayCaster::RayCaster(const Tree& tree) : tree_(&tree) {
  rank_.reserve(static_cast<std::size_t>(tree.depth()));
  for (int l = 0; l < tree.depth(); ++l) rank_.emplace_back(tree.occupancy(l));
}

std::optional<RayHit> RayCaster::cast(const Ray& ray) const {
  check_ray(ray);
  if (tree_->empty()) return std::nullopt;
  const RayAxes axes(ray);
  const int depth = tree_->depth();
  const auto side = static_cast<std::int64_t>(tree_->side());

  // Clip to the cube [0, side]^3: the first event that puts the ray inside it.
  std::array<std::int64_t, 3> v = axes.start;
  double t = 0.0;
  if (std::any_of(v.begin(), v.end(), [&](std::int64_t i) { return i < 0 || i >= side; })) {
    double enter = 0.0, leave = kNever;
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
      leave = std::min(leave, crossing_time(s > 0 ? static_cast<double>(side) : 0.0, o, axes.inverse[a]));
    }
    if (!(enter < leave) || !(enter <= ray.t_max)) return std::nullopt;
    t = enter;
    for (int a = 0; a < 3; ++a)
      if (axes.step[a]) v[a] = index_after(axes, ray, a, t, 0, side - 1);
  }

  RayHit hit;
  hit.t = t;
  if (t > 0.0) {
    for (int a = 0; a < 3; ++a) {
      if (axes.step[a] && crossing_time(axes.entry_plane(a, v[a]), ray.origin[a], axes.inverse[a]) == t) {
        hit.normal[a] = -axes.step[a];
        break;
      }
    }
  }

  // Crossing time of the plane through which the ray leaves v on each axis.
  std::array<double, 3> exit_time{kNever, kNever, kNever};
  for (int a = 0; a < 3; ++a)
    if (axes.step[a]) exit_time[a] = crossing_time(axes.exit_plane(a, v[a]), ray.origin[a], axes.inverse[a]);

  std::array<std::size_t, kMaxDepth> block{};  // block of each level on the current path
  int from = 0;                                // first level whose cell may have changed
  for (;;) {
    // Descend from `from` until a level's cell is empty, or the voxel is occupied.
    int level = from;
    for (;; ++level) {
      const int shift = 2 * (depth - 1 - level);
      const auto bit = static_cast<unsigned>(((v[0] >> shift) & 3) + 4 * ((v[1] >> shift) & 3) +
                                             16 * ((v[2] >> shift) & 3));
      const auto words = tree_->occupancy(level);
      const std::uint64_t word = words[block[level]];
      if (!((word >> bit) & 1u)) break;
      if (level == depth - 1) {
        hit.voxel = Voxel{static_cast<std::uint32_t>(v[0]), static_cast<std::uint32_t>(v[1]),
                          static_cast<std::uint32_t>(v[2])};
        return hit;
      }
      block[level + 1] = rank_[level].before(words, block[level]) +
                         static_cast<std::size_t>(std::popcount(word & ((std::uint64_t{1} << bit) - 1)));
    }

    // Step over the empty node of `level`: to the first event that leaves it. An axis
    // whose own next plane comes later keeps its index; one whose boundary plane is
    // crossed at that event enters the next node; any other crossed planes inside the
    // node on the way (only when the node is bigger than a voxel) are counted exactly.
    const int shift = 2 * (depth - 1 - level);
    std::array<std::int64_t, 3> lo{}, hi{};
    std::array<double, 3> leave{kNever, kNever, kNever};
    double next = kNever;
    for (int a = 0; a < 3; ++a) {
      if (!axes.step[a]) continue;
      lo[a] = (v[a] >> shift) << shift;
      hi[a] = lo[a] + (std::int64_t{1} << shift) - 1;
      leave[a] = shift == 0 ? exit_time[a]
                            : crossing_time(static_cast<double>(axes.step[a] > 0 ? hi[a] + 1 : lo[a]), ray.origin[a],
                                            axes.inverse[a]);
      next = std::min(next, leave[a]);
    }
    if (next == kNever || !(next <= ray.t_max)) return std::nullopt;
    const std::array<std::int64_t, 3> old = v;
    hit.normal = {0, 0, 0};
    bool normal_set = false;
    for (int a = 0; a < 3; ++a) {
      const int s = axes.step[a];
      if (!s || exit_time[a] > next) continue;
      const double o = ray.origin[a];
      v[a] = leave[a] == next ? (s > 0 ? hi[a] + 1 : lo[a] - 1) : index_after(axes, ray, a, next, lo[a], hi[a]);
      if (v[a] < 0 || v[a] >= side) return std::nullopt;
      exit_time[a] = crossing_time(axes.exit_plane(a, v[a]), o, axes.inverse[a]);
      if (!normal_set && crossing_time(axes.entry_plane(a, v[a]), o, axes.inverse[a]) == next) {
        hit.normal[a] = -s;
        normal_set = true;
      }
    }
    hit.t = next;
    const auto changed = static_cast<std::uint64_t>((v[0] ^ old[0]) | (v[1] ^ old[1]) | (v[2] ^ old[2]));
    from = depth - 1 - static_cast<int>(std::bit_width(changed) - 1) / 2;
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
