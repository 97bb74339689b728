#include "vola/audio/response.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <mutex>
#include <numbers>
#include <optional>
#include <sstream>
#include <utility>

#include "vola/audio/attenuation_level.hpp"
#include "vola/audio/convolve.hpp"
#include "vola/builder.hpp"
#include "vola/error.hpp"
#include "option_checks.hpp"
#include "vola/parallel.hpp"
#include "vola/raycast/world.hpp"

namespace vola::audio {

namespace {

// Amplitudes above this (+60 dB re 1 at 1 m: a point a millimetre from a wall) share the top bin.
constexpr double kMaxGainDb = 60.0;

// Attenuation levels run from -offset to count - 1 - offset: +kMaxGainDb down to the floor.
struct LevelRange {
  std::int64_t offset = 0, count = 0;
};
LevelRange level_range(const ResponseOptions& o) {
  LevelRange r;
  r.offset = static_cast<std::int64_t>(std::ceil(kMaxGainDb / o.bin_width_db));
  r.count = r.offset + static_cast<std::int64_t>(std::ceil(-o.floor_db / o.bin_width_db)) + 2;
  return r;
}

// Above this many levels a table of their amplitudes is not worth making.
constexpr std::int64_t kMaxTabulatedLevels = std::int64_t{1} << 20;

int bits_for(std::uint64_t values) {
  int bits = 0;
  while ((std::uint64_t{1} << bits) < values) ++bits;
  return bits;
}

// Everything one voxel's path needs, in grid units (voxels) where possible.
struct PathModel {
  Point source{}, listener{};      // grid coordinates
  double samples_per_voxel = 0.0;  // voxel_size / c * sample_rate
  double amplitude_scale = 0.0;    // sqrt(A / pi) / voxel_size^2 = 1 / (sqrt(pi) * voxel_size)
  std::uint32_t max_sample = 0;
  double floor_amplitude = 0.0;
  std::vector<double> slot_gain;         // broadband coefficient, 1 for per-band materials
  std::vector<std::uint16_t> slot_kernel;  // 0 or the per-band kernel number
  const AcousticScene* scene = nullptr;
  bool visibility = false;
  bool single_slot = false;  // one material: every voxel's slot is 0
  // Bin packing.
  std::int64_t level_offset = 0, level_count = 0;
  std::optional<AttenuationLevels> levels;
  int level_bits = 0, sample_bits = 0, kernel_bits = 0;
};

double distance(const Point& a, const Point& b) noexcept {
  const double dx = a[0] - b[0], dy = a[1] - b[1], dz = a[2] - b[2];
  return std::sqrt(dx * dx + dy * dy + dz * dz);
}

// Does the segment from `from` to the reflecting point reach the voxel (or a voxel touching
// it: a ray arriving at a grazing angle may enter the wall one voxel early)?
bool sees(const raycast::RayCaster& caster, const Point& from, const Point& to, const Voxel& target) {
  const Point d{to[0] - from[0], to[1] - from[1], to[2] - from[2]};
  const auto hit = caster.cast(raycast::Ray{from, d, 1.0});
  if (!hit) return true;
  auto near = [](std::uint32_t a, std::uint32_t b) { return (a > b ? a - b : b - a) <= 1; };
  return near(hit->voxel.x, target.x) && near(hit->voxel.y, target.y) && near(hit->voxel.z, target.z);
}

// What reaches the listener through the reflecting point p of a surface voxel.
struct Arrival {
  double d1 = 0.0, d2 = 0.0;  // the two legs (voxels)
  double sample = 0.0;
  double amplitude = 0.0;
  std::uint16_t slot = 0;
};

// false when the path arrives after the window, is below the floor, or (with visibility)
// is blocked.
// Inlined: it is the per-voxel work of threshold().
[[gnu::always_inline]] inline bool arrives(const PathModel& m, const Point& p, std::uint64_t rank, std::size_t leaf_block, const Voxel& voxel, Arrival& a) {
  a.d1 = distance(m.source, p);
  a.d2 = distance(p, m.listener);
  a.sample = std::nearbyint((a.d1 + a.d2) * m.samples_per_voxel);
  if (!(a.sample <= static_cast<double>(m.max_sample))) return false;
  a.slot = m.single_slot ? 0 : m.scene->materials().slot(rank, leaf_block);
  a.amplitude = m.slot_gain[a.slot] * m.amplitude_scale / (a.d1 * a.d2);
  if (!(a.amplitude >= m.floor_amplitude) || a.amplitude == 0.0) return false;
  return !m.visibility || (sees(m.scene->caster(), m.source, p, voxel) && sees(m.scene->caster(), m.listener, p, voxel));
}

// The path through one surface voxel, or false when it does not reflect toward both ends
// or does not arrive (above). The obvious per-voxel form of what threshold() does per block.
bool reflect(const PathModel& m, const SurfaceVoxel& s, Reflection& out) {
  const double lo[3] = {static_cast<double>(s.voxel.x), static_cast<double>(s.voxel.y), static_cast<double>(s.voxel.z)};
  Point p{lo[0] + 0.5, lo[1] + 0.5, lo[2] + 0.5};
  bool facing = false;
  for (int a = 0; a < 3; ++a) {
    const double hi = lo[a] + 1.0;
    if ((s.exposed & (1u << (2 * a))) && m.source[a] < lo[a] && m.listener[a] < lo[a]) {
      p[a] = lo[a];
      facing = true;
    } else if ((s.exposed & (2u << (2 * a))) && m.source[a] > hi && m.listener[a] > hi) {
      p[a] = hi;
      facing = true;
    }
  }
  if (!facing) return false;
  Arrival a;
  if (!arrives(m, p, s.rank, s.leaf_block, s.voxel, a)) return false;
  out.voxel = s;
  out.point = raycast::grid_to_world(m.scene->frame(), p);
  out.path = (a.d1 + a.d2) * m.scene->frame().voxel_size;
  out.amplitude = a.amplitude;
  out.sample = static_cast<std::uint32_t>(a.sample);
  out.slot = a.slot;
  return true;
}

Key bin_key(const PathModel& m, std::uint16_t slot, double sample, double amplitude) {
  const std::int64_t level = m.levels->index(amplitude);
  return (static_cast<Key>(m.slot_kernel[slot]) << (m.sample_bits + m.level_bits)) |
         (static_cast<Key>(sample) << m.level_bits) | static_cast<Key>(level);
}

// Bits of a block word whose cell coordinate along `axis` is c (0..3).
constexpr std::uint64_t layer(int axis, unsigned c) {
  constexpr std::uint64_t first[3] = {detail::kX0, detail::kY0, detail::kZ0};
  return first[axis] << (c << (2 * axis));
}

// Calls key(Key) for every reflecting voxel of the surface blocks [begin, end): the faces
// that face both ends are found for the whole block with word masks, then the block's
// reflecting voxels go through the model of arrives() in stages over small arrays: the
// distances, delays (and with one material the amplitudes) in a branch-free loop the
// compiler vectorises (the same IEEE operations, so the same values), then the tests and
// the binning.
template <class F>
void block_keys(const PathModel& m, const std::vector<SurfaceBlock>& blocks, std::size_t begin, std::size_t end, F&& key) {
  alignas(16) double px[64], py[64], pz[64], sample[64], product[64], amplitude[64];
  std::uint8_t bits[64];
  const double sx = m.source[0], sy = m.source[1], sz = m.source[2];
  const double lx = m.listener[0], ly = m.listener[1], lz = m.listener[2];
  const double spv = m.samples_per_voxel;
  const double single_gain = m.slot_gain[0] * m.amplitude_scale;
  const bool plain = m.single_slot && !m.visibility;
  for (std::size_t i = begin; i < end; ++i) {
    const SurfaceBlock& b = blocks[i];
    const std::uint32_t origin[3] = {b.origin.x, b.origin.y, b.origin.z};
    std::uint64_t below[3], above[3];  // reflect at the low / high face on each axis
    std::uint64_t reflecting = 0;
    for (int a = 0; a < 3; ++a) {
      std::uint64_t low_ok = 0, high_ok = 0;
      for (unsigned c = 0; c < 4; ++c) {
        const double lo = static_cast<double>(origin[a] + c), hi = lo + 1.0;
        if (m.source[a] < lo && m.listener[a] < lo) low_ok |= layer(a, c);
        if (m.source[a] > hi && m.listener[a] > hi) high_ok |= layer(a, c);
      }
      below[a] = b.exposed[2 * a] & low_ok;
      above[a] = b.exposed[2 * a + 1] & high_ok & ~below[a];
      reflecting |= below[a] | above[a];
    }
    // The reflecting points: the low face, the high face or the centre on each axis (below
    // and above exclude each other).
    static constexpr double kOffset[3] = {0.5, 0.0, 1.0};
    unsigned n = 0;
    for (; reflecting; reflecting &= reflecting - 1, ++n) {
      const unsigned bit = static_cast<unsigned>(std::countr_zero(reflecting));
      bits[n] = static_cast<std::uint8_t>(bit);
      px[n] = static_cast<double>(origin[0] + (bit & 3u)) + kOffset[((below[0] >> bit) & 1) | (((above[0] >> bit) & 1) << 1)];
      py[n] = static_cast<double>(origin[1] + ((bit >> 2) & 3u)) + kOffset[((below[1] >> bit) & 1) | (((above[1] >> bit) & 1) << 1)];
      pz[n] = static_cast<double>(origin[2] + (bit >> 4)) + kOffset[((below[2] >> bit) & 1) | (((above[2] >> bit) & 1) << 1)];
    }
    // As distance() and arrives(): the same operations in the same order.
    for (unsigned j = 0; j < n; ++j) {
      const double ax = sx - px[j], ay = sy - py[j], az = sz - pz[j];
      const double bx = px[j] - lx, by = py[j] - ly, bz = pz[j] - lz;
      const double d1 = std::sqrt(ax * ax + ay * ay + az * az);
      const double d2 = std::sqrt(bx * bx + by * by + bz * bz);
      product[j] = d1 * d2;
      sample[j] = std::nearbyint((d1 + d2) * spv);
      amplitude[j] = single_gain / product[j];
    }
    for (unsigned j = 0; j < n; ++j) {
      if (!(sample[j] <= static_cast<double>(m.max_sample))) continue;
      std::uint16_t slot = 0;
      double a = amplitude[j];
      if (!plain) {
        const unsigned bit = bits[j];
        const std::uint64_t rank = b.first_rank + static_cast<std::uint64_t>(std::popcount(b.word & ((std::uint64_t{1} << bit) - 1)));
        slot = m.single_slot ? 0 : m.scene->materials().slot(rank, b.index);
        a = m.slot_gain[slot] * m.amplitude_scale / product[j];
        if (m.visibility && (a >= m.floor_amplitude && a != 0.0)) {
          const Point p{px[j], py[j], pz[j]};
          const Voxel v{origin[0] + (bit & 3u), origin[1] + ((bit >> 2) & 3u), origin[2] + (bit >> 4)};
          if (!(sees(m.scene->caster(), m.source, p, v) && sees(m.scene->caster(), m.listener, p, v))) continue;
        }
      }
      if (!(a >= m.floor_amplitude) || a == 0.0) continue;
      key(bin_key(m, slot, sample[j], a));
    }
  }
}

struct Direct {
  double distance = 0.0;
  std::uint32_t sample = 0;
  double amplitude = 0.0;
  bool blocked = false;
};

Direct direct_path(const AcousticScene& scene, const Point& source, const Point& listener, const ResponseOptions& o) {
  scene.check_point(source, "the source");
  scene.check_point(listener, "the listener");
  Direct d;
  d.distance = distance(source, listener);
  if (!(d.distance > 0.0)) throw InvalidArgument("the source and the listener are at the same point");
  const double samples = std::nearbyint(d.distance / o.speed_of_sound * o.sample_rate);
  if (!(samples < static_cast<double>(1u << 24)))
    throw InvalidArgument("the source is too far from the listener: the delay exceeds 2^24 samples");
  d.sample = static_cast<std::uint32_t>(samples);
  const Point s = raycast::world_to_grid(scene.frame(), source), l = raycast::world_to_grid(scene.frame(), listener);
  d.blocked = scene.caster().cast(raycast::Ray{s, {l[0] - s[0], l[1] - s[1], l[2] - s[2]}, 1.0}).has_value();
  d.amplitude = d.blocked ? 0.0 : 1.0 / d.distance;
  return d;
}

PathModel path_model(const AcousticScene& scene, const Point& source, const Point& listener, const Direct& direct,
                     const ResponseOptions& o) {
  PathModel m;
  const double size = scene.frame().voxel_size;
  m.source = raycast::world_to_grid(scene.frame(), source);
  m.listener = raycast::world_to_grid(scene.frame(), listener);
  m.samples_per_voxel = size / o.speed_of_sound * o.sample_rate;
  m.amplitude_scale = 1.0 / (std::sqrt(std::numbers::pi) * size);
  const double last = std::ceil((direct.distance / o.speed_of_sound + o.reflection_window) * o.sample_rate);
  if (!(last < static_cast<double>(1u << 24)))
    throw InvalidArgument("the reflection window ends after 2^24 samples: shorten it");
  m.max_sample = static_cast<std::uint32_t>(last);
  m.floor_amplitude = std::pow(10.0, o.floor_db / 20.0);
  std::uint16_t kernels = 0;
  for (const Material& mat : scene.materials().slots()) {
    m.slot_gain.push_back(mat.per_band() ? 1.0 : mat.bands[0]);
    m.slot_kernel.push_back(mat.per_band() ? ++kernels : 0);
  }
  m.scene = &scene;
  m.single_slot = scene.materials().slots().size() == 1;
  m.visibility = o.visibility;
  const LevelRange levels = level_range(o);
  m.level_offset = levels.offset;
  m.level_count = levels.count;
  m.level_bits = bits_for(static_cast<std::uint64_t>(m.level_count));
  m.sample_bits = bits_for(std::uint64_t{m.max_sample} + 1);
  m.kernel_bits = bits_for(std::uint64_t{kernels} + 1);
  if (m.level_bits + m.sample_bits + m.kernel_bits > 64)
    throw OptionError("bin_width_db", "too many attenuation bins: widen `bin_width_db` or raise `floor_db`");
  m.levels.emplace(o.bin_width_db, m.level_offset, m.level_count);
  return m;
}

// Sorts bin keys: the usual ones (kernel, sample and level in at most 24 bits) in two
// counting passes of 12 bits, one pass fewer than radix_sort's 11-bit digits need.
void sort_keys(std::vector<Key>& keys, int key_bits) {
  constexpr int kDigit = 12;
  constexpr std::size_t kBuckets = std::size_t{1} << kDigit;
  if (key_bits > 2 * kDigit) {
    radix_sort(keys, nullptr, std::max(key_bits, 1));
    return;
  }
  std::vector<std::size_t> count(2 * kBuckets, 0);
  for (const Key k : keys) {
    ++count[k & (kBuckets - 1)];
    ++count[kBuckets + ((k >> kDigit) & (kBuckets - 1))];
  }
  std::vector<Key> buffer(keys.size());
  for (int pass = 0; pass < 2; ++pass) {
    std::size_t* c = &count[static_cast<std::size_t>(pass) * kBuckets];
    std::size_t offset = 0;
    for (std::size_t b = 0; b < kBuckets; ++b) offset += std::exchange(c[b], offset);
    const int shift = pass * kDigit;
    for (const Key k : keys) buffer[c[(k >> shift) & (kBuckets - 1)]++] = k;
    keys.swap(buffer);
  }
}

}  // namespace

void ResponseOptions::check() const {
  const auto fail = &detail::refuse_option;
  detail::check_sound_options(sample_rate, speed_of_sound);
  if (!(reflection_window >= 0.0 && reflection_window <= 10.0)) fail("the reflection window must be in [0, 10] s", reflection_window);
  if (!(bin_width_db > 0.0 && bin_width_db <= 6.0)) fail("the bin width must be in (0, 6] dB", bin_width_db);
  if (!(floor_db >= -300.0 && floor_db < 0.0)) fail("the floor must be in [-300, 0) dB", floor_db);
}

struct AcousticScene::AmplitudeCache {
  std::mutex mutex;
  std::vector<std::pair<std::pair<double, double>, std::shared_ptr<const LevelAmplitudes>>> tables;  // (width, floor)
};

AcousticScene::AcousticScene(const Tree& tree, const MaterialTable& materials)
    : tree_(&tree), frame_(tree.frame()), materials_(materials, tree), blocks_(leaf_blocks(tree)),
      surface_(surface_blocks(tree, blocks_)), caster_(tree),
      amplitude_cache_(std::make_unique<AmplitudeCache>()) {
  if (!(frame_.voxel_size > 0.0) || !std::isfinite(frame_.voxel_size))
    throw InvalidArgument("the scene's voxel size is not a positive number");
}

AcousticScene::~AcousticScene() = default;

std::shared_ptr<const LevelAmplitudes> AcousticScene::level_amplitudes(const ResponseOptions& o) const {
  std::lock_guard lock(amplitude_cache_->mutex);
  auto& tables = amplitude_cache_->tables;
  const std::pair<double, double> key{o.bin_width_db, o.floor_db};
  for (const auto& [k, table] : tables)
    if (k == key) return table;
  auto table = std::make_shared<LevelAmplitudes>();
  const LevelRange levels = level_range(o);
  if (levels.count <= kMaxTabulatedLevels) {
    table->low = static_cast<std::int32_t>(-levels.offset);
    table->values.resize(static_cast<std::size_t>(levels.count));
    for (std::size_t i = 0; i < table->values.size(); ++i)
      table->values[i] = std::pow(10.0, -(table->low + static_cast<double>(i)) * o.bin_width_db / 20.0);
  }
  tables.emplace_back(key, table);
  return table;
}

void AcousticScene::check_point(const Point& p, const std::string& what) const {
  for (const double c : p)
    if (!std::isfinite(c)) throw InvalidArgument(what + " has a coordinate that is not a finite number");
  const Point g = raycast::world_to_grid(frame_, p);
  const double side = static_cast<double>(tree_->side());
  if (!(g[0] >= 0 && g[1] >= 0 && g[2] >= 0 && g[0] < side && g[1] < side && g[2] < side)) {
    // Outside the grid nothing is known: no wall, no floor; the scene cannot say what is heard.
    std::ostringstream s;
    const Point hi = raycast::grid_to_world(frame_, {side, side, side});
    s << what << " (" << p[0] << ", " << p[1] << ", " << p[2] << ") is outside the scene's grid, from (" << frame_.origin[0]
      << ", " << frame_.origin[1] << ", " << frame_.origin[2] << ") to (" << hi[0] << ", " << hi[1] << ", " << hi[2] << ")";
    throw InvalidArgument(s.str());
  }
  {
    const Voxel v{static_cast<std::uint32_t>(g[0]), static_cast<std::uint32_t>(g[1]), static_cast<std::uint32_t>(g[2])};
    if (tree_->contains(v)) {
      std::ostringstream s;
      s << what << " (" << p[0] << ", " << p[1] << ", " << p[2] << ") is inside occupied voxel (" << v.x << ", " << v.y
        << ", " << v.z << "): sound cannot start or end inside a wall";
      throw InvalidArgument(s.str());
    }
  }
}

Thresholded threshold(const AcousticScene& scene, const Point& source, const Point& listener, const ResponseOptions& o) {
  o.check();
  const Direct direct = direct_path(scene, source, listener, o);
  const PathModel m = path_model(scene, source, listener, direct, o);
  const unsigned threads = resolve_thread_count(o.threads);
  const std::size_t count = scene.surface().size();
  // A few ranges per thread balance uneven scenes; the counts per key, hence the bins, do not
  // depend on how the blocks are split.
  const std::size_t ranges = std::max<std::size_t>(1, std::min<std::size_t>(count / 256 + 1, 4 * threads));
  std::vector<std::vector<std::pair<Key, std::uint64_t>>> runs(ranges);
  const int key_bits = m.kernel_bits + m.sample_bits + m.level_bits;
  ParallelOptions parallel;
  parallel.threads = threads;
  parallel.chunks = ranges;
  parallel.name = "audio.threshold";
  const auto bin_range = [&](const Chunk& range) {
    std::vector<Key> keys;
    block_keys(m, scene.surface(), range.begin, range.end, [&](Key k) { keys.push_back(k); });
    sort_keys(keys, key_bits);
    auto& run = runs[range.index];
    for (const Key k : keys) {
      if (!run.empty() && run.back().first == k) ++run.back().second;
      else run.emplace_back(k, 1);
    }
  };
  parallel_for(count, bin_range, parallel);
  // The runs sorted by one radix sort of their keys (an index keeps the counts; a scene with
  // 2^32 runs would take 64 GiB of keys and counts first, so 32-bit indices suffice).
  std::vector<Key> keys;
  std::vector<std::uint64_t> counts;
  for (const auto& run : runs)
    for (const auto& [k, n] : run) {
      keys.push_back(k);
      counts.push_back(n);
    }
  std::vector<std::uint32_t> order(keys.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = static_cast<std::uint32_t>(i);
  radix_sort(keys, &order, std::max(key_bits, 1));
  Thresholded t;
  t.direct_distance = direct.distance;
  t.direct_sample = direct.sample;
  t.direct_amplitude = direct.amplitude;
  t.direct_blocked = direct.blocked;
  const Key level_mask = (Key{1} << m.level_bits) - 1, sample_mask = (Key{1} << m.sample_bits) - 1;
  for (std::size_t i = 0; i < keys.size(); ++i) {
    const Key key = keys[i];
    const std::uint64_t n = counts[order[i]];
    t.reflectors += n;
    if (!t.bins.empty()) {
      const Bin& b = t.bins.back();
      const Key last = (static_cast<Key>(b.kernel) << (m.sample_bits + m.level_bits)) |
                       (static_cast<Key>(b.sample) << m.level_bits) | static_cast<Key>(b.level + m.level_offset);
      if (last == key) {
        t.bins.back().count += n;
        continue;
      }
    }
    t.bins.push_back(Bin{static_cast<std::uint16_t>(key >> (m.sample_bits + m.level_bits)),
                         static_cast<std::uint32_t>((key >> m.level_bits) & sample_mask),
                         static_cast<std::int32_t>(static_cast<std::int64_t>(key & level_mask) - m.level_offset), n});
  }
  return t;
}

namespace {

// Out of line and cold: the loops below stay free of calls.
[[noreturn, gnu::cold, gnu::noinline]] void bad_bin(const Bin& b) {
  std::ostringstream s;
  s << "make_filter: bin (kernel " << b.kernel << ", sample " << b.sample << ", level " << b.level
    << ") is not what threshold() gives with these options: bins out of order, or a level outside the floor";
  throw InvalidArgument(s.str());
}

// Adds count * amplitude of bins [begin, end) (all of one kernel, sorted by sample) into h.
// Each sample's bins are added in their order, as a plain loop would (the same sums to the
// bit), but kStreams streams of bins, split where the sample changes, run side by side:
// one stream's additions to a sample form a chain of dependent adds through memory, and
// independent chains overlap (5 was fastest here, from 2 to 16).
constexpr std::size_t kStreams = 5;

void add_bins(const Bin* begin, const Bin* end, const LevelAmplitudes& table, double width, std::vector<double>& h) {
  const double* const values = table.values.data();
  const std::uint64_t levels = table.values.size();
  double* const out = h.data();
  const std::size_t size = h.size();
  if (levels == 0) {  // too many levels to tabulate: a pow per bin
    for (const Bin* b = begin; b != end; ++b) {
      if (b->sample >= size) bad_bin(*b);
      out[b->sample] += static_cast<double>(b->count) * std::pow(10.0, -static_cast<double>(b->level) * width / 20.0);
    }
    return;
  }
  auto add = [&](const Bin& b) {
    const auto level = static_cast<std::uint64_t>(static_cast<std::int64_t>(b.level) - table.low);  // wraps below
    // Memory safety and the table only: a bin of another kernel inside this kernel's run (bins
    // not sorted as threshold() gives them) is not looked for, that test alone would cost a
    // sixth of this loop.
    if (b.sample >= size || level >= levels) bad_bin(b);
    out[b.sample] += static_cast<double>(b.count) * values[level];
  };
  // kStreams streams of about equal length, each boundary moved on to a sample change.
  const std::size_t n = static_cast<std::size_t>(end - begin);
  std::array<const Bin*, kStreams> next{}, stop{};
  const Bin* cut = begin;
  for (std::size_t i = 0; i < kStreams; ++i) {
    next[i] = cut;
    cut = std::max(cut, begin + n * (i + 1) / kStreams);
    while (cut != end && cut != begin && cut[-1].sample == cut->sample) ++cut;  // a sample stays in one stream
    stop[i] = cut;
  }
  // The shortest stream's length: that many rounds take a bin from every stream, unrolled.
  std::size_t rounds = n;
  for (std::size_t i = 0; i < kStreams; ++i) rounds = std::min(rounds, static_cast<std::size_t>(stop[i] - next[i]));
  [&]<std::size_t... I>(std::index_sequence<I...>) {
    for (std::size_t r = 0; r < rounds; ++r) (add(next[I][r]), ...);
    ((next[I] += rounds), ...);
  }(std::make_index_sequence<kStreams>{});
  for (std::size_t i = 0; i < kStreams; ++i)
    for (const Bin* b = next[i]; b != stop[i]; ++b) add(*b);
}

}  // namespace

std::vector<double> make_filter(const AcousticScene& scene, const Thresholded& t, const ResponseOptions& o) {
  o.check();
  const std::shared_ptr<const LevelAmplitudes> table = scene.level_amplitudes(o);
  // The bins come sorted by kernel, then sample: each kernel's last bin has its last sample.
  const Bin* const bins = t.bins.data();
  const Bin* const bins_end = bins + t.bins.size();
  std::vector<std::pair<const Bin*, const Bin*>> runs;  // per kernel present
  std::size_t length = std::size_t{t.direct_sample} + 1;
  std::uint16_t kernels = 0;
  for (const Bin* run = bins; run != bins_end;) {
    const std::uint16_t k = run->kernel;
    const Bin* run_end = std::partition_point(run, bins_end, [k](const Bin& b) { return b.kernel == k; });
    runs.emplace_back(run, run_end);
    length = std::max(length, std::size_t{run_end[-1].sample} + 1);
    kernels = std::max(kernels, k);
    run = run_end;
  }
  std::vector<std::vector<double>> per_kernel(std::size_t{kernels} + 1);
  per_kernel[0].assign(length, 0.0);
  per_kernel[0][t.direct_sample] += t.direct_amplitude;
  for (const auto& [begin, end] : runs) {
    auto& h = per_kernel[begin->kernel];
    if (h.empty()) h.assign(length, 0.0);
    add_bins(begin, end, *table, o.bin_width_db, h);
  }
  std::vector<double> ir = std::move(per_kernel[0]);
  if (kernels == 0) return ir;
  // Per-band materials: their bins through the material's (minimum-phase) filter.
  std::vector<const Material*> band_materials;
  for (const Material& mat : scene.materials().slots())
    if (mat.per_band()) band_materials.push_back(&mat);
  if (band_materials.size() < kernels) throw InvalidArgument("make_filter: the bins name a per-band material the scene lacks");
  for (std::uint16_t k = 1; k <= kernels; ++k) {
    if (per_kernel[k].empty()) continue;
    // From the first arrival on: FFT rounding then cannot put sound before it.
    const auto& h = per_kernel[k];
    const std::size_t first = static_cast<std::size_t>(std::find_if(h.begin(), h.end(), [](double v) { return v != 0.0; }) - h.begin());
    if (first == h.size()) continue;
    const std::vector<double> shaped =
        convolve(std::span<const double>(h).subspan(first), band_kernel(*band_materials[k - 1], o.sample_rate));
    if (ir.size() < first + shaped.size()) ir.resize(first + shaped.size(), 0.0);
    for (std::size_t i = 0; i < shaped.size(); ++i) ir[first + i] += shaped[i];
  }
  return ir;
}

std::vector<Reflection> reflections(const AcousticScene& scene, const Point& source, const Point& listener,
                                    const ResponseOptions& o) {
  o.check();
  const Direct direct = direct_path(scene, source, listener, o);
  const PathModel m = path_model(scene, source, listener, direct, o);
  std::vector<Reflection> out;
  Reflection r;
  for_each_surface_voxel(scene.tree(), scene.blocks(), 0, scene.blocks().size(), [&](const SurfaceVoxel& s) {
    if (reflect(m, s, r)) out.push_back(r);
  });
  return out;
}

std::vector<double> band_kernel(const Material& material, double sample_rate) {
  auto gain = [&](double f) {
    const auto& c = material.bands;
    if (f <= kOctaveBands.front()) return c.front();
    if (f >= kOctaveBands.back()) return c.back();
    const double octave = std::log2(f / kOctaveBands.front());
    const auto i = std::min(static_cast<std::size_t>(octave), c.size() - 2);
    const double frac = octave - static_cast<double>(i);
    return c[i] + (c[i + 1] - c[i]) * frac;
  };
  // A design grid of about 6 Hz, and taps spanning about 1/60 s: enough to tell the 125 Hz
  // band from its neighbours.
  std::size_t n = 1024;
  while (static_cast<double>(n) < sample_rate / 6.0 && n < (std::size_t{1} << 20)) n *= 2;
  std::vector<double> magnitude(n / 2 + 1);
  for (std::size_t k = 0; k < magnitude.size(); ++k) magnitude[k] = gain(static_cast<double>(k) * sample_rate / static_cast<double>(n));
  const auto taps = std::clamp<std::size_t>(static_cast<std::size_t>(sample_rate / 60.0), 32, n);
  return minimum_phase_fir(magnitude, taps);
}

}  // namespace vola::audio
