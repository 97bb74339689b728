// The late tail's energy by stochastic ray tracing over the voxels (room_response.hpp).
#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <numbers>
#include <random>

#include "vola/audio/room_response.hpp"
#include "vola/parallel.hpp"
#include "vola/raycast/world.hpp"

namespace vola::audio {

namespace {

// The rays are traced in chunks of kRaysPerChunk, each with its own random numbers (seeded
// by the chunk's number) and histogram, kChunksPerRound chunks a round; the histograms are
// summed in chunk order, so the result does not depend on the thread count. After each
// round the chunks' spread says how precise the sum is, and tracing stops once it is
// precise enough (RoomOptions::tail_error) or `rays` are traced.
constexpr std::uint64_t kRaysPerChunk = 128;
constexpr std::uint64_t kChunksPerRound = 8;
// Rounds before the spread is trusted: 16 chunks.
constexpr std::uint64_t kMinRounds = 2;
// The precision is judged on windows of this many bins (ms), down to kErrorRange (60 dB)
// below the loudest window.
constexpr std::size_t kErrorWindow = 10;
constexpr double kErrorRange = 1e-6;

// The relative standard error of the sum of n chunks' energies per window (sum and
// squares hold per window the sum of the chunks' energies and of their squares), root
// mean square over the windows within kErrorRange of the loudest: the typical error of a
// window's level (a relative error e is about 4.3 e dB).
double tail_relative_error(const std::vector<double>& sum, const std::vector<double>& squares, double n) {
  if (n < 2.0) return std::numeric_limits<double>::infinity();
  double loudest = 0.0;
  for (const double e : sum) loudest = std::max(loudest, e);
  if (!(loudest > 0.0)) return std::numeric_limits<double>::infinity();
  double total = 0.0;
  std::size_t windows = 0;
  for (std::size_t w = 0; w < sum.size(); ++w) {
    if (!(sum[w] >= kErrorRange * loudest)) continue;
    // The chunks' sample variance times n: the variance of their sum.
    const double variance = std::max(0.0, squares[w] - sum[w] * sum[w] / n) * n / (n - 1.0);
    total += variance / (sum[w] * sum[w]);
    ++windows;
  }
  return std::sqrt(total / static_cast<double>(windows));
}

// The random numbers of chunk c: its own generator, seeded by a hash (splitmix64's
// finaliser) of the seed and c, so neighbouring chunks' seeds share no bits.
std::uint64_t chunk_seed(std::uint64_t seed, std::uint64_t c) noexcept {
  std::uint64_t z = seed * 0x9E3779B97F4A7C15ull + (c + 1) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

// The distance (grid units) from p to the nearest occupied voxel, searched up to `limit`.
double clearance(const Tree& tree, const Point& p, double limit) {
  const auto side = static_cast<std::int64_t>(tree.side());
  const auto reach = static_cast<std::int64_t>(std::ceil(limit)) + 1;
  const std::int64_t c[3] = {static_cast<std::int64_t>(std::floor(p[0])), static_cast<std::int64_t>(std::floor(p[1])),
                             static_cast<std::int64_t>(std::floor(p[2]))};
  double best = limit;
  for (std::int64_t z = std::max<std::int64_t>(0, c[2] - reach); z <= std::min(side - 1, c[2] + reach); ++z)
    for (std::int64_t y = std::max<std::int64_t>(0, c[1] - reach); y <= std::min(side - 1, c[1] + reach); ++y)
      for (std::int64_t x = std::max<std::int64_t>(0, c[0] - reach); x <= std::min(side - 1, c[0] + reach); ++x) {
        // Distance from p to the cube [x, x+1] x ...: per axis the gap outside the interval.
        const std::int64_t v[3] = {x, y, z};
        double d2 = 0.0;
        for (int a = 0; a < 3; ++a) {
          const double gap = std::max({static_cast<double>(v[a]) - p[a], p[a] - static_cast<double>(v[a] + 1), 0.0});
          d2 += gap * gap;
        }
        if (d2 >= best * best) continue;
        if (tree.contains(static_cast<std::uint32_t>(x), static_cast<std::uint32_t>(y), static_cast<std::uint32_t>(z)))
          best = std::sqrt(d2);
      }
  return best;
}

// A direction Lambert-distributed (cosine-weighted) about unit n.
Point lambert(const Point& n, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const double r2 = u(rng), phi = 2.0 * std::numbers::pi * u(rng);
  const double r = std::sqrt(r2), up = std::sqrt(1.0 - r2);
  // An orthonormal basis (t, b, n).
  const Point helper = std::abs(n[0]) < 0.9 ? Point{1, 0, 0} : Point{0, 1, 0};
  Point t{helper[1] * n[2] - helper[2] * n[1], helper[2] * n[0] - helper[0] * n[2], helper[0] * n[1] - helper[1] * n[0]};
  const double tl = std::sqrt(t[0] * t[0] + t[1] * t[1] + t[2] * t[2]);
  for (double& v : t) v /= tl;
  const Point b{n[1] * t[2] - n[2] * t[1], n[2] * t[0] - n[0] * t[2], n[0] * t[1] - n[1] * t[0]};
  const double ct = r * std::cos(phi), cb = r * std::sin(phi);
  return {ct * t[0] + cb * b[0] + up * n[0], ct * t[1] + cb * b[1] + up * n[1], ct * t[2] + cb * b[2] + up * n[2]};
}

Point uniform_direction(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const double z = 2.0 * u(rng) - 1.0, phi = 2.0 * std::numbers::pi * u(rng);
  const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
  return {r * std::cos(phi), r * std::sin(phi), z};
}

double dot(const Point& a, const Point& b) noexcept { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

Point reflect(const Point& d, const Point& n) noexcept {
  const double k = 2.0 * dot(d, n);
  return {d[0] - k * n[0], d[1] - k * n[1], d[2] - k * n[2]};
}

}  // namespace

LateEnergy late_energy(const Room& room, const Point& source, const Point& listener, int order, const RoomOptions& o) {
  o.check();
  const AcousticScene& scene = room.scene();
  const Frame& frame = scene.frame();
  const double voxel = frame.voxel_size;
  const Point s = raycast::world_to_grid(frame, source), l = raycast::world_to_grid(frame, listener);
  LateEnergy late;
  late.bin_samples = std::max<std::size_t>(1, static_cast<std::size_t>(std::lround(o.sample_rate / 1000.0)));
  const double bin_seconds = static_cast<double>(late.bin_samples) / o.sample_rate;
  const auto bins = static_cast<std::size_t>(std::ceil(o.max_length / bin_seconds)) + 1;
  if (o.rays == 0) return late;
  // The receiver: a sphere clear of every voxel (rays never enter walls, so a sphere cut by
  // one would hear too little), at most 64 voxels across the search.
  const double wanted = std::min(o.receiver_radius / voxel, 64.0);
  const double radius = std::min(wanted, clearance(scene.tree(), l, wanted));
  late.receiver_radius = radius * voxel;
  // A listener on a voxel's face has no room for a sphere: it hears the diffuse rain only.
  const double r2 = radius * radius;
  const double volume = 4.0 / 3.0 * std::numbers::pi * late.receiver_radius * late.receiver_radius * late.receiver_radius;
  // Rays start with energy 1 and the sum is scaled at the end by 4 pi / N (m^2) for the N
  // rays traced: a free field then gives energy 1 / d^2 at d, the direct sound's squared
  // amplitude.
  const double min_energy = std::pow(10.0, o.decay_floor_db / 10.0);
  const double max_distance = o.max_length * o.speed_of_sound / voxel;  // grid units
  const double bins_per_voxel = voxel / o.speed_of_sound / bin_seconds;
  const SurfacePatches& surface = room.patches();
  const auto& patches = surface.patches();

  // Whether the listener sees an exposed face (from its centre), asked once per face for
  // the diffuse rain: 0 not asked yet, 1 seen, 2 hidden. A face's answer is the same
  // whichever thread asks first, so the cache changes no result.
  std::vector<std::atomic<std::uint8_t>> sees(surface.element_count());
  for (auto& v : sees) v.store(0, std::memory_order_relaxed);
  auto listener_sees = [&](std::int64_t element, const Voxel& v, int axis, int sign) {
    auto& known = sees[static_cast<std::size_t>(element)];
    const std::uint8_t k = known.load(std::memory_order_relaxed);
    if (k) return k == 1;
    Point from{v.x + 0.5, v.y + 0.5, v.z + 0.5};
    from[axis] += 0.5 * sign + 1e-7 * sign;
    const Point to{l[0] - from[0], l[1] - from[1], l[2] - from[2]};
    // The segment stops just short of the listener: one on a face still hears that side.
    const bool seen = !scene.caster().cast(raycast::Ray{from, to, 1.0 - 1e-9}).has_value();
    known.store(seen ? 1 : 2, std::memory_order_relaxed);
    return seen;
  };

  const Bands air = air_attenuation(o);
  // The energy left after `metres` of air, per band.
  auto air_loss = [&](double metres, Bands& e) {
    if (!o.air) return;
    for (std::size_t b = 0; b < e.size(); ++b) e[b] *= std::pow(10.0, -air[b] * metres / 10.0);
  };
  auto add = [](Bands& to, const Bands& e, double scale) {
    for (std::size_t b = 0; b < e.size(); ++b) to[b] += e[b] * scale;
  };
  // One chunk's rays into its histogram; returns the earliest deposit (grid units of path).
  auto trace_chunk = [&](std::uint64_t chunk, std::vector<Bands>& histogram) {
    double earliest = max_distance;
    std::mt19937_64 rng(chunk_seed(o.seed, chunk));
    std::uniform_real_distribution<double> u(0.0, 1.0);
    const std::uint64_t first = chunk * kRaysPerChunk, last = std::min(o.rays, first + kRaysPerChunk);
    for (std::uint64_t ray = first; ray < last; ++ray) {
      Point origin = s, d = uniform_direction(rng);
      Bands energy;
      energy.fill(1.0);
      double travelled = 0.0;
      int reflections = 0;
      bool specular = true, last_specular = true;
      while (travelled < max_distance) {
        const double remaining = max_distance - travelled;
        const auto hit = scene.caster().cast(raycast::Ray{origin, d, remaining});
        const double segment = hit ? hit->t : remaining;
        // The chord of the receiver sphere on [0, segment]: for paths whose last reflection was
        // specular (diffuse ones reached the listener as rain, below), unless the image sources
        // hold the path.
        if (r2 > 0.0 && last_specular && !(specular && reflections <= order)) {
          const Point w{l[0] - origin[0], l[1] - origin[1], l[2] - origin[2]};
          const double along = dot(w, d);
          const double h2 = dot(w, w) - along * along;
          if (h2 < r2) {
            const double half = std::sqrt(r2 - h2);
            const double t0 = std::max(0.0, along - half), t1 = std::min(segment, along + half);
            if (t1 > t0) {
              const auto bin = static_cast<std::size_t>((travelled + 0.5 * (t0 + t1)) * bins_per_voxel);
              if (bin < bins) {
                Bands e = energy;
                air_loss(0.5 * (t0 + t1) * voxel, e);
                add(histogram[bin], e, (t1 - t0) * voxel / volume);
              }
              earliest = std::min(earliest, travelled + t0);
            }
          }
        }
        if (!hit) break;
        const auto& n = hit->normal;
        const int axis = n[0] != 0 ? 0 : n[1] != 0 ? 1 : n[2] != 0 ? 2 : -1;
        if (axis < 0) break;  // started inside a voxel: cannot happen from an empty cell
        const int face = 2 * axis + (n[axis] > 0 ? 1 : 0);
        Point face_normal{0, 0, 0};
        face_normal[axis] = n[axis];
        // A face a ray enters from an empty cell is exposed, so it is in a patch.
        std::uint32_t patch = 0;
        const std::int64_t element = surface.element_of(hit->voxel, face, patch);
        if (element < 0) break;
        const auto p = static_cast<std::size_t>(patch);
        const Point normal = patches[p].normal;
        const Bands& r = room.band_reflection()[p];
        air_loss(segment * voxel, energy);
        double strongest = 0.0;
        for (std::size_t b = 0; b < energy.size(); ++b) {
          energy[b] *= r[b] * r[b];
          strongest = std::max(strongest, energy[b]);
        }
        if (strongest < min_energy) break;
        travelled += segment;
        for (int a = 0; a < 3; ++a) origin[a] += segment * d[a];
        ++reflections;
        // Diffuse rain: the part s of the energy scattered here (Lambert: cos(theta) / pi per
        // steradian) that reaches the listener straight, energy s cos(theta) / (pi D^2), if it
        // sees the listener (from the face's centre). Every reflection contributes, so the
        // tail is smooth even where few rays pass the receiver (open scenes).
        if (o.scattering > 0.0) {
          const Point to{l[0] - origin[0], l[1] - origin[1], l[2] - origin[2]};
          const double distance = std::sqrt(dot(to, to));
          const double cosine = dot(to, normal) / distance;
          if (cosine > 0.0 && dot(to, face_normal) > 0.0 && listener_sees(element, hit->voxel, axis, n[axis])) {
            const auto bin = static_cast<std::size_t>((travelled + distance) * bins_per_voxel);
            const double metres = distance * voxel;
            if (bin < bins) {
              Bands e = energy;
              air_loss(metres, e);
              add(histogram[bin], e, o.scattering * cosine / (std::numbers::pi * metres * metres));
            }
            earliest = std::min(earliest, travelled + distance);
          }
        }
        last_specular = !(u(rng) < o.scattering);
        if (!last_specular) {
          d = lambert(normal, rng);
          specular = false;
        } else {
          d = reflect(d, normal);
        }
        // Out through the face that was hit: a fitted normal can send a grazing ray back in.
        if (!(dot(d, face_normal) > 1e-9)) d = reflect(d, face_normal);
        if (!(dot(d, face_normal) > 1e-9)) d = face_normal;
        // Just off the face, in the empty cell it faces.
        origin[axis] = std::round(origin[axis]) + 1e-7 * n[axis];
      }
    }
    return earliest;
  };

  // Rounds of chunks; per bin the sum of the chunks' energies (the bands' mean) and of their
  // squares, for the spread.
  const std::uint64_t chunks = (o.rays + kRaysPerChunk - 1) / kRaysPerChunk;
  late.bands.assign(bins, Bands{});
  const std::size_t windows = (bins + kErrorWindow - 1) / kErrorWindow;
  std::vector<double> sum(windows, 0.0), squares(windows, 0.0);
  std::vector<std::vector<Bands>> partial(kChunksPerRound);
  std::vector<double> earliest(kChunksPerRound);
  double first_path = max_distance;
  std::uint64_t traced = 0, rounds = 0;
  ParallelOptions parallel;
  parallel.threads = o.threads;
  parallel.name = "audio.late_energy";
  while (traced < chunks) {
    const std::uint64_t count = std::min(kChunksPerRound, chunks - traced);
    parallel.chunks = static_cast<std::size_t>(count);
    parallel_for(static_cast<std::size_t>(count), [&](const Chunk& c) {
      partial[c.index].assign(bins, Bands{});
      earliest[c.index] = trace_chunk(traced + c.index, partial[c.index]);
    }, parallel);
    for (std::uint64_t c = 0; c < count; ++c) {
      first_path = std::min(first_path, earliest[c]);
      const std::vector<Bands>& h = partial[c];
      for (std::size_t w = 0; w < windows; ++w) {
        double e = 0.0;
        for (std::size_t i = w * kErrorWindow; i < std::min(bins, (w + 1) * kErrorWindow); ++i)
          for (std::size_t b = 0; b < h[i].size(); ++b) {
            late.bands[i][b] += h[i][b];
            e += h[i][b];
          }
        sum[w] += e;
        squares[w] += e * e;
      }
    }
    traced += count;
    ++rounds;
    if (o.tail_error > 0.0 && rounds >= kMinRounds && traced < chunks &&
        tail_relative_error(sum, squares, static_cast<double>(traced)) <= o.tail_error)
      break;
  }
  const std::uint64_t rays = std::min(o.rays, traced * kRaysPerChunk);
  late.rays = rays;
  late.relative_error = tail_relative_error(sum, squares, static_cast<double>(traced));
  const double ray_energy = 4.0 * std::numbers::pi / static_cast<double>(rays);
  late.energy.assign(bins, 0.0);
  for (std::size_t i = 0; i < bins; ++i) {
    double total = 0.0;
    for (double& e : late.bands[i]) {
      e *= ray_energy;
      total += e;
    }
    late.energy[i] = total / static_cast<double>(late.bands[i].size());
  }
  late.first_sample = static_cast<std::size_t>(std::ceil(first_path * voxel / o.speed_of_sound * o.sample_rate));
  // Trailing empty bins carry nothing.
  while (!late.energy.empty() && late.energy.back() == 0.0) {
    late.energy.pop_back();
    late.bands.pop_back();
  }
  return late;
}

}  // namespace vola::audio
