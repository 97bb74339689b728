// Loading little-endian values from unaligned bytes: the one place every reader of
// binary formats (LAS, PLY, PCD, attribute columns) takes them from. vola supports
// little-endian hosts only (src/core/bytes.hpp says why), so a load is one memcpy, which
// compilers turn into a plain move.
#pragma once

#include <bit>
#include <cstring>

namespace vola {

static_assert(std::endian::native == std::endian::little, "vola's binary readers assume a little-endian host");

template <class T>
inline T load_le(const void* bytes) noexcept {
  T value;
  std::memcpy(&value, bytes, sizeof(T));
  return value;
}

}  // namespace vola
