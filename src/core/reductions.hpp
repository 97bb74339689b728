// Internal: the per-voxel attribute reductions (mean, max, min, majority, last), written
// once for the in-memory builder (build) and the streaming builder (StreamBuilder).
// Every reduction but majority keeps one partial value per voxel, and partials combine
// associatively (older points first), so a voxel's value does not depend on how its
// points were chunked. NaN rules: NaN is a point without a value (a LAS no_data, a
// scanner's missing return): mean skips it (the mean of the voxel's numbers; NaN when
// it has none), max and min skip it unless every value is NaN (fmax/fmin); majority
// counts NaN as one value that sorts after every number.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <type_traits>
#include <vector>

#include "vola/attributes.hpp"
#include "vola/version.hpp"

namespace vola {
VOLA_INLINE_NAMESPACE_BEGIN
namespace detail {

// Values in a total order for majority: NaN (of any payload) after every number and equal
// to every other NaN, so that sorting has a strict weak order and grouping equal values
// never stalls on NaN != NaN (a text file with "nan" in a majority column once made the
// reduction loop forever).
inline bool value_before(double a, double b) noexcept { return std::isnan(b) ? !std::isnan(a) : a < b; }
inline bool same_value(double a, double b) noexcept { return a == b || (std::isnan(a) && std::isnan(b)); }
// The one representative of a class of same_value values that a majority stores: +0 for
// either zero, the default quiet NaN for any NaN. Which member a sort puts first is
// not specified, so without this the stored bytes would depend on the algorithm.
inline double canonical_value(double v) noexcept {
  if (std::isnan(v)) return std::numeric_limits<double>::quiet_NaN();
  return v == 0.0 ? 0.0 : v;
}

// What a value adds to a mean's sum: NaN adds -0, the sum's identity (-0 + x is x for
// every x, -0 and +0 included), so the sum is that of the voxel's numbers in input
// order, bit for bit, whichever path folds them.
inline double mean_summand(double v) noexcept { return std::isnan(v) ? -0.0 : v; }

// The partial of older points combined with the partial of newer ones. mean: the sum
// (finish() divides); last: the newer. Not for majority, whose partial is a histogram.
template <Reduction R>
inline double combine(double older, double newer) noexcept {
  static_assert(R != Reduction::majority, "majority partials are (value, count) pairs");
  if constexpr (R == Reduction::mean) return older + newer;
  else if constexpr (R == Reduction::max) return std::fmax(older, newer);
  else if constexpr (R == Reduction::min) return std::fmin(older, newer);
  else return newer;
}

// f(std::integral_constant<Reduction, R>{}) for a reduction known at run time, so that
// loops over voxels are compiled once per reduction with no switch inside. Not majority.
template <class F>
decltype(auto) with_reduction(Reduction r, F&& f) {
  switch (r) {
    case Reduction::mean: return f(std::integral_constant<Reduction, Reduction::mean>{});
    case Reduction::max: return f(std::integral_constant<Reduction, Reduction::max>{});
    case Reduction::min: return f(std::integral_constant<Reduction, Reduction::min>{});
    default: return f(std::integral_constant<Reduction, Reduction::last>{});
  }
}

// The partial of n >= 1 points, value_at(k) the k-th in input order (a mean's: the sum
// of the values that are numbers).
template <Reduction R, class ValueAt>
inline double fold(ValueAt&& value_at, std::uint32_t n) {
  if constexpr (R == Reduction::mean) {
    double sum = mean_summand(value_at(0));
    for (std::uint32_t k = 1; k < n; ++k) sum += mean_summand(value_at(k));
    return sum;
  } else {
    double partial = value_at(0);
    for (std::uint32_t k = 1; k < n; ++k) partial = combine<R>(partial, value_at(k));
    return partial;
  }
}

// How many of n values, value_at(k) the k-th, are NaN (a mean's points without a value).
template <class ValueAt>
inline std::uint32_t count_nan(ValueAt&& value_at, std::uint32_t n) {
  std::uint32_t nans = 0;
  for (std::uint32_t k = 0; k < n; ++k) nans += std::isnan(value_at(k)) ? 1u : 0u;
  return nans;
}

// A voxel's value from its partial and its number of points; for a mean, `points` counts
// the points with a value (a mean of none is NaN: -0 / 0).
inline double finish(Reduction r, double partial, std::uint64_t points) noexcept {
  return r == Reduction::mean ? partial / static_cast<double>(points) : partial;
}

// Majority: sorts `values` and calls emit(value, count) for each distinct value, in order.
template <class Emit>
void distinct_counts(std::vector<double>& values, Emit&& emit) {
  std::sort(values.begin(), values.end(), value_before);
  for (std::size_t s = 0; s < values.size();) {
    std::size_t e = s + 1;
    while (e < values.size() && same_value(values[e], values[s])) ++e;
    emit(values[s], static_cast<std::uint32_t>(e - s));
    s = e;
  }
}

// The most frequent of `values` (reordered); ties go to the smallest value, so the
// result does not depend on input order.
inline double majority_of(std::vector<double>& values) {
  double best = values.front();
  std::uint32_t best_count = 0;
  distinct_counts(values, [&](double value, std::uint32_t count) {
    if (count > best_count) best = value, best_count = count;
  });
  return canonical_value(best);
}

}  // namespace detail
VOLA_INLINE_NAMESPACE_END
}  // namespace vola
