// Internal: logistic mixing of several bit predictions, in integers only, for the
// mixed occupancy coder (levels flags 4, docs/FILE_FORMAT.md). Each context model gives
// a probability; the mixer adds their logits (log(p / (1 - p))) with weights it learns
// online by gradient descent on coding cost, and an adaptive probability map refines the
// result in a small context. This is the textbook context-mixing construction (as in the
// PAQ family of compressors), written from the idea, not from their code. Everything is
// integer arithmetic with fixed tables so that the encoder and the decoder compute the
// same probabilities on every machine: the probabilities are part of the file format.
#pragma once

#include <array>
#include <cstdint>

#include "range_coder.hpp"
#include "vola/version.hpp"

namespace vola {
VOLA_INLINE_NAMESPACE_BEGIN
namespace detail {

// Logits are in 1/256 of a nat, clipped to [-2047, 2047]; probabilities of a 1 in 1/4096.
// squash(d) = 4096 / (1 + e^(-d/256)), interpolated between its values at every 128.
inline int squash(int d) noexcept {
  // round(4096 / (1 + exp(-(i - 16) / 2))) for i = 0..32.
  static constexpr std::array<int, 33> kLogistic = {1,    2,    4,    6,    10,   17,   27,   45,   74,   120,  194,
                                                    311,  488,  747,  1102, 1546, 2048, 2550, 2994, 3349, 3608, 3785,
                                                    3902, 3976, 4022, 4051, 4069, 4079, 4086, 4090, 4092, 4094, 4095};
  if (d > 2047) d = 2047;
  if (d < -2047) d = -2047;
  const int i = (d + 2048) >> 7, w = (d + 2048) & 127;
  return (kLogistic[static_cast<std::size_t>(i)] * (128 - w) + kLogistic[static_cast<std::size_t>(i + 1)] * w + 64) >> 7;
}

// stretch(p) = the logit of p (1/4096 units): the inverse of squash, by table.
class StretchTable {
 public:
  StretchTable() noexcept {
    int p = 0;
    for (int d = -2047; d <= 2047; ++d) {
      const int s = squash(d);
      for (; p <= s; ++p) table_[static_cast<std::size_t>(p)] = static_cast<std::int16_t>(d);
    }
    for (; p < 4096; ++p) table_[static_cast<std::size_t>(p)] = 2047;
  }
  int operator()(int p) const noexcept { return table_[static_cast<std::size_t>(p)]; }

 private:
  std::array<std::int16_t, 4096> table_{};
};

inline int stretch(int p) noexcept {
  static const StretchTable table;
  return table(p);
}

// The logit of a BitModel's probability (it keeps the probability of a 0 in 1/65536).
inline int logit_of(const BitModel& m) noexcept {
  const int p1 = (65535 - m.p) >> 4;
  return stretch(p1 < 1 ? 1 : (p1 > 4095 ? 4095 : p1));
}

// K logits mixed with one of `Sets` weight vectors (chosen per bit by a small context).
template <int K, int Sets>
class Mixer {
 public:
  Mixer() noexcept {
    for (auto& set : weights_) set.fill(kInitialWeight);
  }
  // The mixed logit of `logits` with weight set `set` (remembered for update()).
  int mix(const std::array<int, K>& logits, unsigned set) noexcept {
    logits_ = logits;
    set_ = set;
    std::int64_t dot = 0;
    for (int k = 0; k < K; ++k) dot += static_cast<std::int64_t>(weights_[set][k]) * logits[k];
    const std::int64_t d = dot >> 16;
    return static_cast<int>(d > 2047 ? 2047 : (d < -2047 ? -2047 : d));
  }
  // Moves the weights along the gradient of the coding cost of `bit` (p1: the mixed
  // probability in 1/4096). Learning rate ~0.003 in nats. Weights stay within +-64: far
  // beyond what data drives them to, and no stream, however long, can overflow them.
  void update(bool bit, int p1) noexcept {
    const int error = ((bit ? 1 : 0) << 12) - p1;
    for (int k = 0; k < K; ++k) {
      const int moved = weights_[set_][k] + ((logits_[k] * error * 3) >> 14);
      weights_[set_][k] = moved > kWeightLimit ? kWeightLimit : (moved < -kWeightLimit ? -kWeightLimit : moved);
    }
  }

 private:
  static constexpr int kInitialWeight = 13107;  // 0.2 in 16.16
  static constexpr int kWeightLimit = 64 << 16;
  std::array<std::array<int, K>, Sets> weights_;
  std::array<int, K> logits_{};
  unsigned set_ = 0;
};

// An adaptive probability map: per context, 33 probabilities (1/65536) over the logit
// range; the prediction interpolates the two around the mixed logit and both move
// toward the bit seen (rate 1/64, shared by their interpolation weights).
template <int Contexts>
class ProbabilityMap {
 public:
  ProbabilityMap() noexcept {
    for (auto& row : rows_)
      for (int i = 0; i < 33; ++i) row[static_cast<std::size_t>(i)] = static_cast<std::uint16_t>(squash((i - 16) * 128) * 16);
  }
  // The refined probability of a 1 (1/65536) for logit `d` in context `context`.
  int refine(int d, unsigned context) noexcept {
    const int at = d + 2048;
    index_ = &rows_[context][static_cast<std::size_t>(at >> 7)];
    weight_ = at & 127;
    return (index_[0] * (128 - weight_) + index_[1] * weight_) >> 7;
  }
  void update(bool bit) noexcept {
    const int target = bit ? 65535 : 0;
    index_[0] = static_cast<std::uint16_t>(index_[0] + ((((target - index_[0]) >> 6) * (128 - weight_)) >> 7));
    index_[1] = static_cast<std::uint16_t>(index_[1] + ((((target - index_[1]) >> 6) * weight_) >> 7));
  }

 private:
  std::array<std::array<std::uint16_t, 33>, Contexts> rows_;
  std::uint16_t* index_ = nullptr;
  int weight_ = 0;
};

// The probability of a 0 (1/65536, within [32, 65504]) the range coder takes, from the
// mixer's and the map's probabilities of a 1, averaged.
inline std::uint32_t zero_probability(int mixed_p1_4096, int refined_p1_65536) noexcept {
  const int p1 = (mixed_p1_4096 * 16 + refined_p1_65536) >> 1;
  const int p0 = 65536 - p1;
  return static_cast<std::uint32_t>(p0 < 32 ? 32 : (p0 > 65504 ? 65504 : p0));
}

}  // namespace detail
VOLA_INLINE_NAMESPACE_END
}  // namespace vola
