#include "vola/map/occupancy_map.hpp"

#include <algorithm>
#include <string>

#include "ray_voxels.hpp"
#include "vola/error.hpp"
#include "vola/parallel.hpp"
#include "voxel_set.hpp"

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

// What one worker collects from its rays of a scan.
struct WorkerSets {
  detail::VoxelSet hit, passed;
  ScanReport report;
};

// One ray into a worker's sets. Cells are in range: both ends are, and the walk stays
// inside their box.
// Grid units by division, as voxel_of: floor(x * (1 / R)) would differ from floor(x / R)
// where x / R rounds across an integer.
void cast(const Point& origin, const Point& point, double size, double max_range, WorkerSets& out) {
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
  detail::walk_ray(o, e, [&](const detail::Cell& c) { out.passed.insert(OccupancyMap::pack(index_of(c))); });
  if (hit) out.hit.insert(OccupancyMap::pack(index_of(detail::cell_of(e))));
}

// The scan's updates, whatever worker found them: hits win over passes (OctoMap's
// computeUpdate), so `passed` ends up holding only the voxels that get a miss.
WorkerSets merge(std::vector<WorkerSets>& sets) {
  WorkerSets all = std::move(sets[0]);
  for (std::size_t w = 1; w < sets.size(); ++w) {
    sets[w].hit.for_each([&](std::uint64_t key) { all.hit.insert(key); });
    sets[w].passed.for_each([&](std::uint64_t key) { all.passed.insert(key); });
    all.report.not_finite += sets[w].report.not_finite;
    all.report.outside += sets[w].report.outside;
    all.report.cut += sets[w].report.cut;
  }
  detail::VoxelSet free;
  all.passed.for_each([&](std::uint64_t key) {
    if (!all.hit.contains(key)) free.insert(key);
  });
  all.passed = std::move(free);
  return all;
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

std::optional<float> OccupancyMap::log_odds(const VoxelIndex& v) const {
  const auto it = cells_.find(pack(v));
  if (it == cells_.end()) return std::nullopt;
  return it->second;
}

std::vector<std::pair<VoxelIndex, float>> OccupancyMap::voxels() const {
  std::vector<std::pair<VoxelIndex, float>> out;
  out.reserve(cells_.size());
  for (const auto& [key, value] : cells_) out.emplace_back(unpack(key), value);
  std::sort(out.begin(), out.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  return out;
}

ScanReport OccupancyMap::insert_scan(std::span<const double> xyz, const Point& origin, double max_range,
                                     unsigned threads) {
  if (!voxel_of(origin))
    throw InvalidArgument("sensor origin (" + std::to_string(origin[0]) + ", " + std::to_string(origin[1]) + ", " +
                          std::to_string(origin[2]) + ") is not finite or outside the map's index range");
  if (!(max_range >= 0.0)) throw InvalidArgument("max_range must be >= 0 (0: no limit)");
  if (xyz.size() % 3 != 0) throw InvalidArgument("xyz must hold 3 coordinates per point");
  const std::size_t count = xyz.size() / 3;
  const unsigned workers = resolve_thread_count(threads);
  std::vector<WorkerSets> sets(workers);
  parallel_for(
      count,
      [&](const Chunk& chunk) {
        WorkerSets& mine = sets[chunk.worker];
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
      },
      ParallelOptions{.threads = workers, .grain = 2048, .name = "map.insert_scan"});
  WorkerSets scan = merge(sets);
  // One update per voxel, as OctoMap's updateNode: add, then clamp (a voxel already at
  // the bound stays there, which is what OctoMap's early abort amounts to).
  const auto update = [&](std::uint64_t key, float change) {
    float& value = cells_.try_emplace(key, 0.0f).first->second;
    value = std::clamp(value + change, model_.clamp_min, model_.clamp_max);
  };
  scan.passed.for_each([&](std::uint64_t key) { update(key, model_.miss); });
  scan.hit.for_each([&](std::uint64_t key) { update(key, model_.hit); });
  scan.report.points = count;
  scan.report.hit_voxels = scan.hit.size();
  scan.report.free_voxels = scan.passed.size();
  return scan.report;
}

}  // namespace vola::map
