// Internal: attribute values in a total order for the majority reduction. NaN (of any
// payload) sorts after every number and equals every other NaN, so that sorting has a
// strict weak order and grouping equal values never stalls on NaN != NaN (a text file
// with "nan" in a majority column once made the reduction loop forever).
#pragma once

#include <cmath>

#include "vola/version.hpp"

namespace vola {
VOLA_INLINE_NAMESPACE_BEGIN
namespace detail {

inline bool value_before(double a, double b) noexcept { return std::isnan(b) ? !std::isnan(a) : a < b; }
inline bool same_value(double a, double b) noexcept { return a == b || (std::isnan(a) && std::isnan(b)); }

}  // namespace detail
VOLA_INLINE_NAMESPACE_END
}  // namespace vola
