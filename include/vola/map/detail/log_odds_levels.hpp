// The occupancy map's log-odds as 16-bit levels: level q stands for
// clamp_min + q (clamp_max - clamp_min) / N, so level 0 is clamp_min and level N is
// clamp_max exactly, and a voxel costs 2 bytes instead of a float's 4.
//
// Updates are exact in the level domain: a hit adds `hit_steps`, a miss adds `miss_steps`
// (the model's log-odds rounded once to whole steps), and clamping is a clamp to [0, N],
// so insertion stays independent of order and thread count and incremental insertion
// equals batch insertion bit for bit. N (32768 .. 65535) is chosen per model so that hit
// and miss are as close to whole steps as possible: with OctoMap's defaults N = 63189, a
// step is 8.7e-5 log-odds, hit and miss are whole steps to within 0.006 of a step (5e-7),
// and 0, where voxels start, lies 0.03 of a step (3e-6) from a level. A value therefore
// differs from OctoMap's float sum by at most 3e-6 + 5e-7 per update, far below the
// distance from the threshold of any sum of hits and misses.
//
// value(q) is the level as a float (what maps report and files store); level_of(value(q))
// == q for every level, so a saved map is read back exactly. Decisions compare value(q)
// with the model's occupied_at, as for a float.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace vola::map::detail {

class LogOddsLevels {
 public:
  using Level = std::uint16_t;

  LogOddsLevels() = default;
  LogOddsLevels(float hit, float miss, float clamp_min, float clamp_max) noexcept
      : clamp_min_(clamp_min), clamp_max_(clamp_max) {
    const double range = static_cast<double>(clamp_max) - clamp_min;
    double best = 1e300;
    if (range > 0.0)
      for (std::uint32_t n = 32768; n <= 65535; ++n) {
        const double step = range / n;
        const double h = hit / step, m = miss / step;
        const double error = std::abs(h - std::nearbyint(h)) + std::abs(m - std::nearbyint(m));
        if (error < best) best = error, levels_ = n;
      }
    if (!(range > 0.0)) {  // clamp_min == clamp_max: one level, always occupied_at
      levels_ = 0;
      return;
    }
    step_ = range / levels_;
    // At least one step each way, so that a hit always raises and a miss always lowers.
    hit_steps_ = std::max<std::int32_t>(1, static_cast<std::int32_t>(std::nearbyint(hit / step_)));
    miss_steps_ = std::min<std::int32_t>(-1, static_cast<std::int32_t>(std::nearbyint(miss / step_)));
    zero_ = level_of(0.0f);
  }

  std::uint32_t levels() const noexcept { return levels_; }  // N: the top level
  double step() const noexcept { return step_; }
  Level zero() const noexcept { return zero_; }  // where a voxel starts (log-odds 0)

  float value(Level q) const noexcept {
    if (q >= levels_) return clamp_max_;
    return static_cast<float>(clamp_min_ + q * step_);
  }
  // The nearest level of a log-odds value in [clamp_min, clamp_max].
  Level level_of(float v) const noexcept {
    if (levels_ == 0) return 0;
    const double q = std::nearbyint((static_cast<double>(v) - clamp_min_) / step_);
    return static_cast<Level>(q <= 0.0 ? 0.0 : (q >= levels_ ? levels_ : q));
  }
  Level hit(Level q) const noexcept {
    const std::int32_t next = std::int32_t{q} + hit_steps_;
    return static_cast<Level>(next > static_cast<std::int32_t>(levels_) ? levels_ : next);
  }
  Level miss(Level q) const noexcept {
    const std::int32_t next = std::int32_t{q} + miss_steps_;
    return static_cast<Level>(next < 0 ? 0 : next);
  }

 private:
  float clamp_min_ = 0.0f, clamp_max_ = 0.0f;
  std::uint32_t levels_ = 65535;
  double step_ = 0.0;
  std::int32_t hit_steps_ = 0, miss_steps_ = 0;
  Level zero_ = 0;
};

}  // namespace vola::map::detail
