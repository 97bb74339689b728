#include "vola/audio/attenuation_level.hpp"

#include <algorithm>
#include <bit>
#include <cmath>

namespace vola::audio {

namespace {

// Above this many levels the edge table would cost more than it saves: exact formula only.
constexpr std::int64_t kMaxTableLevels = std::int64_t{1} << 20;
constexpr double kMargin = 1e-9;

}  // namespace

AttenuationLevels::AttenuationLevels(double bin_width_db, std::int64_t offset, std::int64_t count)
    : inverse_width_(1.0 / bin_width_db),
      levels_per_log2_(-20.0 * std::log10(2.0) / bin_width_db),
      offset_(offset),
      count_(count) {
  if (count_ > kMaxTableLevels || count_ < 1) return;
  for (std::size_t i = 0; i < mantissa_log2_.size(); ++i) mantissa_log2_[i] = std::log2(1.0 + (static_cast<double>(i) + 0.5) / 2048.0);
  edge_below_.assign(static_cast<std::size_t>(count_), 0.0);
  edge_above_.assign(static_cast<std::size_t>(count_), 0.0);
  for (std::int64_t i = 0; i + 1 < count_; ++i) {
    const double edge = std::pow(10.0, -(static_cast<double>(i - offset_) + 0.5) * bin_width_db / 20.0);
    edge_below_[static_cast<std::size_t>(i)] = edge * (1.0 - kMargin);
    edge_above_[static_cast<std::size_t>(i)] = edge * (1.0 + kMargin);
  }
}

std::int64_t AttenuationLevels::exact_index(double amplitude) const noexcept {
  const auto level = static_cast<std::int64_t>(std::llround(-20.0 * std::log10(amplitude) * inverse_width_));
  return std::clamp<std::int64_t>(level + offset_, 0, count_ - 1);
}

}  // namespace vola::audio
