#include "vola/map/occupancy_map.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <string>

#include "ray_voxels.hpp"
#include "vola/error.hpp"
#include "vola/parallel.hpp"

namespace vola::map {

namespace {

constexpr int kIndexBits = 21;
constexpr std::uint64_t kIndexMask = (std::uint64_t{1} << kIndexBits) - 1;

bool in_range(const detail::Cell& c) noexcept {
  for (const std::int64_t v : c)
    if (v < -kIndexLimit || v >= kIndexLimit) return false;
  return true;
}

VoxelIndex index_of(const detail::Cell& c) noexcept {
  return {static_cast<std::int32_t>(c[0]), static_cast<std::int32_t>(c[1]), static_cast<std::int32_t>(c[2])};
}

// Blocks of 4x4x4 voxels: block (i >> 2, j >> 2, k >> 2), bit (i & 3) + 4 (j & 3) + 16 (k & 3)
// (the VOLA order), keys of 19 bits per axis.
constexpr int kBlockBits = kIndexBits - 2;
constexpr std::int64_t kBlockOffset = std::int64_t{1} << (kBlockBits - 1);
constexpr std::uint64_t kBlockMask = (std::uint64_t{1} << kBlockBits) - 1;

std::uint64_t block_key(const detail::Cell& c) noexcept {
  const auto field = [](std::int64_t v) { return static_cast<std::uint64_t>((v >> 2) + kBlockOffset) & kBlockMask; };
  return field(c[0]) | field(c[1]) << kBlockBits | field(c[2]) << (2 * kBlockBits);
}

std::uint64_t bit_of(const detail::Cell& c) noexcept {
  return std::uint64_t{1} << ((c[0] & 3) | (c[1] & 3) << 2 | (c[2] & 3) << 4);
}

struct Masks {
  std::uint64_t passed = 0, hit = 0;
};

// One worker's masks of blocks the map does not have yet.
class FreshBlocks {
 public:
  // The position of `key`'s masks, added empty when new.
  std::uint32_t find_or_add(std::uint64_t key) {
    bool added = false;
    const std::uint32_t at = index_.find_or_add(key, added);
    if (added) {
      keys_.push_back(key);
      masks_.emplace_back();
    }
    return at;
  }
  std::size_t size() const noexcept { return keys_.size(); }
  std::uint64_t key(std::size_t b) const noexcept { return keys_[b]; }
  Masks& masks(std::size_t b) noexcept { return masks_[b]; }

 private:
  detail::BlockIndex index_;
  std::vector<std::uint64_t> keys_;
  std::vector<Masks> masks_;
};

// What one worker's rays of a scan pass and hit. Consecutive voxels of a ray mostly share
// a block, so the bits of the current block gather in two words; when the ray enters
// another block they go into a small direct-mapped cache of recent blocks (neighbouring
// rays enter the same blocks), which writes a block's bits back when another block takes
// its slot, and at the end: into the scan's masks of a block the map has (an atomic OR,
// skipped when the bits are there already), or into the worker's fresh blocks.
class ScanWorker {
 public:
  ScanWorker(const detail::BlockIndex& map, std::vector<Masks>& pending) : map_(&map), pending_(&pending) {}

  void pass(const detail::Cell& c) { at(c).passed |= bit_of(c); }
  void hit(const detail::Cell& c) { at(c).hit |= bit_of(c); }
  // The current block's bits into the cache.
  void flush() {
    if (key_ == detail::BlockIndex::kEmpty) return;
    Recent& r = recent_[(key_ * 0x9e3779b97f4a7c15ull) >> (64 - kRecentBits)];
    if (r.key != key_) {
      write_back(r);
      r.key = key_;
    }
    r.bits.passed |= bits_.passed;
    r.bits.hit |= bits_.hit;
    bits_ = {};
    key_ = detail::BlockIndex::kEmpty;
    base_ = kNoCell;
  }
  // Everything into the scan's and the fresh masks.
  void drain() {
    flush();
    for (Recent& r : recent_) write_back(r);
  }

  FreshBlocks fresh;
  ScanReport report;

 private:
  struct Recent {
    std::uint64_t key = detail::BlockIndex::kEmpty;
    Masks bits;
  };
  static constexpr int kRecentBits = 11;

  void write_back(Recent& r) {
    if (r.key == detail::BlockIndex::kEmpty) return;
    const std::int64_t b = map_->size() == 0 ? -1 : map_->find(r.key);
    if (b < 0) {
      Masks& m = fresh.masks(fresh.find_or_add(r.key));
      m.passed |= r.bits.passed;
      m.hit |= r.bits.hit;
    } else {
      Masks& m = (*pending_)[static_cast<std::size_t>(b)];
      or_into(m.passed, r.bits.passed);
      or_into(m.hit, r.bits.hit);
    }
    r = {};
  }
  static void or_into(std::uint64_t& word, std::uint64_t bits) {
    if (!bits) return;
    std::atomic_ref<std::uint64_t> shared(word);
    if ((shared.load(std::memory_order_relaxed) & bits) != bits) shared.fetch_or(bits, std::memory_order_relaxed);
  }
  // Cells of one block differ only in their two low bits: the test is three XORs.
  Masks& at(const detail::Cell& c) {
    if (((c[0] ^ base_[0]) | (c[1] ^ base_[1]) | (c[2] ^ base_[2])) & ~std::int64_t{3}) {
      flush();
      base_ = c;
      key_ = block_key(c);
    }
    return bits_;
  }

  const detail::BlockIndex* map_;
  std::vector<Masks>* pending_;
  std::vector<Recent> recent_ = std::vector<Recent>(std::size_t{1} << kRecentBits);
  std::uint64_t key_ = detail::BlockIndex::kEmpty;
  // A cell of the current block, or one beyond the index range (no cell's block) when none.
  static constexpr detail::Cell kNoCell{std::int64_t{1} << 40, 0, 0};
  detail::Cell base_ = kNoCell;
  Masks bits_;
};

// One ray into a worker's masks. Cells are in range: both ends are, and the walk stays
// inside their box.
// Grid units by division, as voxel_of: floor(x * (1 / R)) would differ from floor(x / R)
// where x / R rounds across an integer.
void cast(const Point& origin, const Point& point, double size, double max_range, ScanWorker& out) {
  const detail::GridPoint o{origin[0] / size, origin[1] / size, origin[2] / size};
  Point end = point;
  bool hit = true;
  if (max_range > 0.0) {
    const double dx = point[0] - origin[0], dy = point[1] - origin[1], dz = point[2] - origin[2];
    const double length = std::sqrt(dx * dx + dy * dy + dz * dz);
    if (length > max_range) {
      const double f = max_range / length;
      end = {origin[0] + dx * f, origin[1] + dy * f, origin[2] + dz * f};
      hit = false;
      ++out.report.cut;
    }
  }
  const detail::GridPoint e{end[0] / size, end[1] / size, end[2] / size};
  detail::walk_ray(o, e, [&](const detail::Cell& c) { out.pass(c); });
  if (hit) out.hit(detail::cell_of(e));
}

}  // namespace

void SensorModel::check() const {
  for (const float v : {hit, miss, clamp_min, clamp_max, occupied_at})
    if (!std::isfinite(v)) throw OptionError("sensor_model", "log-odds must be finite");
  if (!(hit > 0.0f)) throw OptionError("hit", "the hit log-odds must be > 0 (probability > 0.5)");
  if (!(miss < 0.0f)) throw OptionError("miss", "the miss log-odds must be < 0 (probability < 0.5)");
  if (!(clamp_min <= occupied_at && occupied_at <= clamp_max))
    throw OptionError("occupied_at", "must lie between clamp_min and clamp_max");
}

OccupancyMap::OccupancyMap(double voxel_size, SensorModel model) : voxel_size_(voxel_size), model_(model) {
  if (!std::isfinite(voxel_size) || !(voxel_size > 0.0))
    throw OptionError("voxel_size", "must be finite and > 0, got " + std::to_string(voxel_size));
  model_.check();
  levels_ = detail::LogOddsLevels(model_.hit, model_.miss, model_.clamp_min, model_.clamp_max);
}

std::size_t OccupancyMap::block_of(std::uint64_t key) {
  bool added = false;
  const std::uint32_t at = index_.find_or_add(key, added);
  if (added) {
    if ((block_count_ >> kPageBits) == pages_.size()) pages_.emplace_back(std::size_t{1} << kPageBits);
    block_at(block_count_).key = key;
    ++block_count_;
  }
  return at;
}

std::uint64_t OccupancyMap::pack(const VoxelIndex& v) noexcept {
  const auto field = [](std::int32_t x) {
    return static_cast<std::uint64_t>(static_cast<std::int64_t>(x) + kIndexLimit) & kIndexMask;
  };
  return field(v.i) | field(v.j) << kIndexBits | field(v.k) << (2 * kIndexBits);
}

VoxelIndex OccupancyMap::unpack(std::uint64_t key) noexcept {
  const auto field = [&](int shift) {
    return static_cast<std::int32_t>(static_cast<std::int64_t>((key >> shift) & kIndexMask) - kIndexLimit);
  };
  return {field(0), field(kIndexBits), field(2 * kIndexBits)};
}

std::optional<VoxelIndex> OccupancyMap::voxel_of(const Point& p) const noexcept {
  detail::GridPoint g{};
  for (int a = 0; a < 3; ++a) {
    g[a] = p[a] / voxel_size_;
    // Also rejects NaN; the bound keeps the floor's cast to int64 defined.
    if (!(std::abs(g[a]) < 4.0 * kIndexLimit)) return std::nullopt;
  }
  const detail::Cell c = detail::cell_of(g);
  if (!in_range(c)) return std::nullopt;
  return index_of(c);
}

VoxelIndex OccupancyMap::voxel_at(std::uint64_t key, int bit) noexcept {
  const auto axis = [&](int field, int low) {
    const std::int64_t b = static_cast<std::int64_t>((key >> (field * kBlockBits)) & kBlockMask) - kBlockOffset;
    return static_cast<std::int32_t>(b * 4 + low);
  };
  return {axis(0, bit & 3), axis(1, (bit >> 2) & 3), axis(2, (bit >> 4) & 3)};
}

std::optional<float> OccupancyMap::log_odds(const VoxelIndex& v) const {
  const detail::Cell c{v.i, v.j, v.k};
  const std::int64_t block = index_.find(block_key(c));
  if (block < 0) return std::nullopt;
  const Block& b = block_at(static_cast<std::size_t>(block));
  const std::uint64_t bit = bit_of(c);
  if (!(b.known & bit)) return std::nullopt;
  return levels_.value(b.level[static_cast<std::size_t>(__builtin_ctzll(bit))]);
}

std::vector<std::pair<VoxelIndex, float>> OccupancyMap::voxels() const {
  std::vector<std::pair<VoxelIndex, float>> out;
  out.reserve(known_);
  for_each([&](const VoxelIndex& v, float value) { out.emplace_back(v, value); });
  std::sort(out.begin(), out.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  return out;
}

void OccupancyMap::restore(const VoxelIndex& v, float log_odds) {
  if (!(log_odds >= model_.clamp_min && log_odds <= model_.clamp_max))
    throw InvalidArgument("log-odds " + std::to_string(log_odds) + " is outside the map's clamping range");
  const detail::Cell c{v.i, v.j, v.k};
  if (!in_range(c)) throw InvalidArgument("voxel outside the map's index range");
  Block& block = block_at(block_of(block_key(c)));
  const std::uint64_t bit = bit_of(c);
  if (!(block.known & bit)) ++known_;
  block.known |= bit;
  block.level[static_cast<std::size_t>(__builtin_ctzll(bit))] = levels_.level_of(log_odds);
}

std::size_t OccupancyMap::memory_bytes() const noexcept {
  return index_.memory_bytes() + pages_.capacity() * sizeof(std::vector<Block>) +
         pages_.size() * (sizeof(Block) << kPageBits);
}

RayExtent ray_extent(std::span<const double> xyz, const Point& origin, double voxel_size, double max_range) {
  RayExtent e;
  double sum = 0.0;
  for (std::size_t n = 0; n + 2 < xyz.size(); n += 3) {
    const double dx = xyz[n] - origin[0], dy = xyz[n + 1] - origin[1], dz = xyz[n + 2] - origin[2];
    const double d = std::sqrt(dx * dx + dy * dy + dz * dz);
    if (!std::isfinite(d)) continue;
    ++e.finite;
    sum += d;
    e.longest = std::max(e.longest, d);
    // A ray crosses at most |dx| + |dy| + |dz| voxel faces, fewer when max_range cuts it.
    const double scale = max_range > 0.0 && d > max_range ? max_range / d : 1.0;
    e.voxel_steps += (std::abs(dx) + std::abs(dy) + std::abs(dz)) * scale / voxel_size;
  }
  e.mean = e.finite ? sum / static_cast<double>(e.finite) : 0.0;
  return e;
}

ScanReport OccupancyMap::insert_scan(std::span<const double> xyz, const Point& origin, double max_range,
                                     unsigned threads) {
  if (!voxel_of(origin)) {
    char what[640];
    const double reach = static_cast<double>(kIndexLimit) * voxel_size_;
    std::snprintf(what, sizeof what,
                  "sensor origin (%.10g, %.10g, %.10g) is not finite or outside the map's index range: the map "
                  "holds %lld voxels each way from 0, i.e. within %.10g of 0 on each axis at voxels of %.10g; give "
                  "scan poses in a local frame (subtract a fixed offset from every pose and point, e.g. a UTM "
                  "corner) or a larger voxel size",
                  origin[0], origin[1], origin[2], static_cast<long long>(kIndexLimit), reach, voxel_size_);
    throw InvalidArgument(what);
  }
  if (!(max_range >= 0.0)) throw InvalidArgument("max_range must be >= 0 (0: no limit)");
  if (xyz.size() % 3 != 0) throw InvalidArgument("xyz must hold 3 coordinates per point");
  const std::size_t count = xyz.size() / 3;
  const unsigned workers = resolve_thread_count(threads);
  // The scan's masks of the map's blocks; blocks new to the map go to the workers first.
  std::vector<Masks> pending(block_count_);
  std::vector<ScanWorker> scans(workers, ScanWorker(index_, pending));
  parallel_for(
      count,
      [&](const Chunk& chunk) {
        ScanWorker& mine = scans[chunk.worker];
        for (std::size_t n = chunk.begin; n < chunk.end; ++n) {
          const Point p{xyz[3 * n], xyz[3 * n + 1], xyz[3 * n + 2]};
          if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2])) {
            ++mine.report.not_finite;
            continue;
          }
          if (!voxel_of(p)) {
            ++mine.report.outside;
            continue;
          }
          cast(origin, p, voxel_size_, max_range, mine);
        }
        mine.flush();
      },
      ParallelOptions{.threads = workers, .grain = 2048, .name = "map.insert_scan"});
  // The workers' cached bits, drained in parallel (one worker each; the scan's masks take
  // atomic ORs).
  parallel_for(
      scans.size(), [&](const Chunk& chunk) { scans[chunk.index].drain(); },
      ParallelOptions{.threads = workers, .grain = 1, .name = "map.insert_scan"});
  ScanReport report;
  report.points = count;
  // New blocks join the map in worker order (block numbers do not reach the map's
  // voxels or files); each worker's masks are freed once merged.
  for (ScanWorker& w : scans) {
    report.not_finite += w.report.not_finite;
    report.outside += w.report.outside;
    report.cut += w.report.cut;
    for (std::size_t b = 0; b < w.fresh.size(); ++b) {
      const std::size_t at = block_of(w.fresh.key(b));
      if (at == pending.size()) pending.emplace_back();
      pending[at].passed |= w.fresh.masks(b).passed;
      pending[at].hit |= w.fresh.masks(b).hit;
    }
    w.fresh = {};
  }
  // One update per voxel, as OctoMap's updateNode: add, then clamp (a voxel already at
  // the bound stays there, which is what OctoMap's early abort amounts to). A voxel both
  // hit and passed counts as hit (OctoMap's computeUpdate). Blocks are independent.
  struct Counts {
    std::uint64_t hit = 0, free = 0, fresh = 0;
  };
  std::vector<Counts> counts(workers);
  parallel_for(
      pending.size(),
      [&](const Chunk& chunk) {
        Counts& c = counts[chunk.worker];
        for (std::size_t b = chunk.begin; b < chunk.end; ++b) {
          const Masks& m = pending[b];
          if (!(m.passed | m.hit)) continue;
          Block& block = block_at(b);
          const std::uint64_t free = m.passed & ~m.hit;
          const std::uint64_t fresh = (free | m.hit) & ~block.known;
          for (std::uint64_t bits = fresh; bits; bits &= bits - 1)
            block.level[static_cast<std::size_t>(__builtin_ctzll(bits))] = levels_.zero();
          block.known |= fresh;
          for (std::uint64_t bits = free; bits; bits &= bits - 1) {
            auto& q = block.level[static_cast<std::size_t>(__builtin_ctzll(bits))];
            q = levels_.miss(q);
          }
          for (std::uint64_t bits = m.hit; bits; bits &= bits - 1) {
            auto& q = block.level[static_cast<std::size_t>(__builtin_ctzll(bits))];
            q = levels_.hit(q);
          }
          c.fresh += static_cast<std::uint64_t>(__builtin_popcountll(fresh));
          c.hit += static_cast<std::uint64_t>(__builtin_popcountll(m.hit));
          c.free += static_cast<std::uint64_t>(__builtin_popcountll(free));
        }
      },
      ParallelOptions{.threads = workers, .grain = 4096, .name = "map.apply_scan"});
  for (const Counts& c : counts) {
    known_ += c.fresh;
    report.hit_voxels += c.hit;
    report.free_voxels += c.free;
  }
  return report;
}

}  // namespace vola::map
