// A mutable probabilistic occupancy map that takes range scans the way OctoMap does and
// freezes into a VOLA state map (state_map.hpp).
//
// Voxel (i, j, k) covers [i*R, (i+1)*R) on each axis, i = floor(x / R), so voxel indices
// line up cell for cell with OctoMap's keys (key = i + 32768) when R is a power of two
// (OctoMap computes floor(x * (1/R)), which differs from floor(x / R) only where x / R
// rounds across an integer).
//
// A voxel holds a log-odds, 0 before its first update. One scan is one batch, as in
// OctoMap's insertPointCloud (computeUpdate, then updateNode):
//  - every point is a ray from the sensor origin; the voxels it passes get a miss and its
//    end voxel (the one holding the point) a hit;
//  - "passes" is exact: a voxel is passed when the segment origin -> point spends a
//    positive length inside it (cells half-open), plus the origin's own voxel; the end
//    voxel is never passed; a ray through an edge or corner does not pass the voxels it
//    only touches there;
//  - a voxel both hit and passed in one scan counts as hit; every voxel gets at most one
//    update per scan, so the result does not depend on point order or thread count;
//  - a point farther than max_range (when > 0) is cut at max_range: the segment up to the
//    cut point passes voxels as above (the cut point's voxel excluded) and nothing is hit;
//  - an update adds the hit or miss log-odds and clamps to [clamp_min, clamp_max].
// Log-odds are held as 16-bit levels between the clamps (detail/log_odds_levels.hpp):
// updates are exact integer steps there, and a value differs from OctoMap's float sum by
// at most 3e-6 + 5e-7 per update it has had (OctoMap's defaults; a step is 8.7e-5); what
// the map reports and saves is the level's float, which restore() maps back to the same
// level.
//
// Storage, as VOLA's own: 4x4x4 blocks, each its key, a 64-bit word of known voxels (bit
// x + 4y + 16z) and 64 levels (144 bytes), in fixed pages (growing never copies the map),
// found through one open-addressing hash of block keys. A scan's rays mark the voxels they
// pass and hit as bits, gathered per block while a ray stays in it and then in a small
// cache of each worker's recent blocks (neighbouring rays enter the same blocks); a block
// leaving the cache takes one probe and one atomic OR into the scan's masks of a block the
// map has, or goes into the worker's own masks of blocks new to the map (the only part
// merged serially). Every block's masks are then applied in parallel: a scan touches only
// the blocks it changes, and memory follows the map (its blocks, plus 16 bytes per block
// during a scan), never the scans already inserted.
//
// Costs: a scan of n rays of m voxels each is O(n m) bit operations plus at most one probe
// per block a ray enters (fewer where the cache holds it), run in parallel with
// vola::parallel_for.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "vola/frame.hpp"
#include "vola/map/detail/block_index.hpp"
#include "vola/map/detail/log_odds_levels.hpp"
#include "vola/tree.hpp"

namespace vola::map {

// OctoMap's conversion, kept bit for bit: the float of log(p / (1 - p)) in double.
inline float log_odds(double probability) noexcept {
  return static_cast<float>(std::log(probability / (1.0 - probability)));
}

// OctoMap's defaults (OccupancyOcTreeBase): hit 0.7, miss 0.4, clamping 0.1192 / 0.971,
// occupied at probability 0.5 and above.
struct SensorModel {
  float hit = log_odds(0.7);
  float miss = log_odds(0.4);
  float clamp_min = log_odds(0.1192);
  float clamp_max = log_odds(0.971);
  float occupied_at = log_odds(0.5);
  // Throws OptionError unless every value is finite, hit > 0 > miss and
  // clamp_min <= occupied_at <= clamp_max.
  void check() const;
};

struct VoxelIndex {
  std::int32_t i = 0, j = 0, k = 0;
  friend bool operator==(const VoxelIndex&, const VoxelIndex&) = default;
  friend auto operator<=>(const VoxelIndex&, const VoxelIndex&) = default;
};

// Indices span -kIndexLimit .. kIndexLimit - 1 per axis (21 bits each, packed in one
// 64-bit hash key): +-104 km at 0.1 m voxels.
inline constexpr std::int32_t kIndexLimit = 1 << 20;

struct ScanReport {
  std::uint64_t points = 0;        // points offered
  std::uint64_t not_finite = 0;    // skipped: a NaN or infinite coordinate
  std::uint64_t outside = 0;       // skipped: voxel index beyond +-kIndexLimit
  std::uint64_t cut = 0;           // beyond max_range: free up to it, no hit
  std::uint64_t hit_voxels = 0;    // voxels updated as hit
  std::uint64_t free_voxels = 0;   // voxels updated as free
};

// How far a scan's rays reach, before it is inserted: a scan whose rays cross far more
// voxels than expected is a mistake more often than a scan (points in survey coordinates
// with a sensor pose near 0, or the voxel size in the wrong unit), and each voxel crossed
// may become a known voxel of ~40 bytes, so callers refuse it up front (`vola map
// --max-ray-voxels`, Python `Map.insert(..., max_ray_voxels=)`).
struct RayExtent {
  double voxel_steps = 0.0;   // at most this many voxels crossed in all (|dx|+|dy|+|dz| / R per ray)
  double longest = 0.0;       // the farthest point's distance from the sensor
  double mean = 0.0;          // the points' mean distance from the sensor
  std::uint64_t finite = 0;   // points with finite coordinates (the others are skipped)
};
// max_range > 0 cuts each ray at it, as insert_scan does.
RayExtent ray_extent(std::span<const double> xyz, const Point& origin, double voxel_size, double max_range);

class OccupancyMap {
 public:
  // Throws OptionError ("voxel_size") unless voxel_size is finite and > 0.
  explicit OccupancyMap(double voxel_size, SensorModel model = {});

  // One scan: xyz holds x y z per point in the world frame; origin is the sensor's
  // position. Throws InvalidArgument when the origin is not finite or outside the index
  // range, or max_range is negative or NaN. threads = 0: vola::thread_count().
  ScanReport insert_scan(std::span<const double> xyz, const Point& origin, double max_range = 0.0,
                         unsigned threads = 0);

  // Sets a voxel's log-odds as a saved map had it (thaw, state_map.hpp): the voxel becomes
  // known, at the level nearest the value (the same level for a value this map reported).
  // Throws InvalidArgument for a value outside [clamp_min, clamp_max] or NaN.
  void restore(const VoxelIndex& v, float log_odds);

  double voxel_size() const noexcept { return voxel_size_; }
  const SensorModel& model() const noexcept { return model_; }
  std::size_t size() const noexcept { return known_; }
  // The voxel holding a world point (floor(x / R) per axis); nullopt when not finite or
  // outside the index range.
  std::optional<VoxelIndex> voxel_of(const Point& p) const noexcept;
  // The log-odds of a voxel, nullopt when never updated (unknown).
  std::optional<float> log_odds(const VoxelIndex& v) const;
  bool occupied(float value) const noexcept { return value >= model_.occupied_at; }
  // Every known voxel with its log-odds, sorted by index.
  std::vector<std::pair<VoxelIndex, float>> voxels() const;
  // Visits every known voxel, in no particular order: f(const VoxelIndex&, float log_odds).
  template <class F>
  void for_each(F&& f) const {
    for (std::size_t b = 0; b < block_count_; ++b) {
      const Block& block = block_at(b);
      for (std::uint64_t bits = block.known; bits; bits &= bits - 1) {
        const int bit = __builtin_ctzll(bits);
        f(voxel_at(block.key, bit), levels_.value(block.level[static_cast<std::size_t>(bit)]));
      }
    }
  }

  // Packing of indices into one 63-bit key (exposed for the tests).
  static std::uint64_t pack(const VoxelIndex& v) noexcept;
  static VoxelIndex unpack(std::uint64_t key) noexcept;

  // Bytes the map holds (blocks and their index), for memory reports.
  std::size_t memory_bytes() const noexcept;
  std::size_t block_count() const noexcept { return block_count_; }
  // The levels log-odds are held in (the step a value is rounded to).
  const detail::LogOddsLevels& levels() const noexcept { return levels_; }

 private:
  struct Block {
    std::uint64_t key = 0;
    std::uint64_t known = 0;                            // bit x + 4y + 16z: the voxel was updated
    std::array<detail::LogOddsLevels::Level, 64> level{};  // meaningful where known
  };
  // Pages of 512 blocks (72 KiB): at most one page is partly empty.
  static constexpr std::size_t kPageBits = 9;
  static constexpr std::size_t kPageMask = (std::size_t{1} << kPageBits) - 1;

  double voxel_size_;
  SensorModel model_;
  detail::LogOddsLevels levels_;
  detail::BlockIndex index_;             // block key -> block number
  std::vector<std::vector<Block>> pages_;
  std::size_t block_count_ = 0;
  std::size_t known_ = 0;

  Block& block_at(std::size_t b) noexcept { return pages_[b >> kPageBits][b & kPageMask]; }
  const Block& block_at(std::size_t b) const noexcept { return pages_[b >> kPageBits][b & kPageMask]; }
  // The block of `key`, added (empty) when the map has none.
  std::size_t block_of(std::uint64_t key);
  static VoxelIndex voxel_at(std::uint64_t block_key, int bit) noexcept;
};

// freeze(map) (state_map.hpp) stores the map as one VOLA tree of its known voxels with
// their occupied/free states and log-odds.

}  // namespace vola::map
