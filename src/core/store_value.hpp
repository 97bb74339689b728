// Internal: a double stored as one attribute value type (store_value, AttributeColumn::set),
// as a template for loops that know the type.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstring>
#include <limits>
#include <type_traits>

#include "vola/attributes.hpp"
#include "vola/version.hpp"

namespace vola {
VOLA_INLINE_NAMESPACE_BEGIN
namespace detail {

template <class T>
inline void store_as(std::byte* p, double value) noexcept {
  T v;
  if constexpr (std::is_floating_point_v<T>) {
    v = static_cast<T>(value);
  } else {
    // Round to nearest and clamp, so that a mean of integers stays in range.
    double r = std::isnan(value) ? 0.0 : std::nearbyint(value);
    r = std::clamp(r, static_cast<double>(std::numeric_limits<T>::lowest()),
                   static_cast<double>(std::numeric_limits<T>::max()));
    v = r >= static_cast<double>(std::numeric_limits<T>::max()) ? std::numeric_limits<T>::max()
                                                                 : static_cast<T>(r);
  }
  std::memcpy(p, &v, sizeof(T));
}

// f(T{}) for the C++ type of a value type.
template <class F>
decltype(auto) with_value_type(ValueType type, F&& f) {
  switch (type) {
    case ValueType::u8: return f(std::uint8_t{});
    case ValueType::u16: return f(std::uint16_t{});
    case ValueType::u32: return f(std::uint32_t{});
    case ValueType::u64: return f(std::uint64_t{});
    case ValueType::i8: return f(std::int8_t{});
    case ValueType::i16: return f(std::int16_t{});
    case ValueType::i32: return f(std::int32_t{});
    case ValueType::i64: return f(std::int64_t{});
    case ValueType::f32: return f(float{});
    default: return f(double{});
  }
}

}  // namespace detail
VOLA_INLINE_NAMESPACE_END
}  // namespace vola
