// Internal to the NPY reader: loading a stored value of either byte order, and the
// fields of a structured dtype (src/io/npy_records.cpp).
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "vola/io/npy.hpp"
#include "vola/little_endian.hpp"

namespace vola::io {

// A value of type T stored little-endian, or big-endian when `swap`.
template <class T>
T load_npy_value(const std::uint8_t* p, bool swap) noexcept {
  if (!swap) return load_le<T>(p);
  std::uint8_t reversed[sizeof(T)];
  for (std::size_t b = 0; b < sizeof(T); ++b) reversed[b] = p[sizeof(T) - 1 - b];
  return load_le<T>(reversed);
}

// numpy's descr list ("[('x', '<f8'), ('rgb', '|u1', (3,)), ...]", from its '[' on): the
// numeric fields with their offsets (subarrays as one field per element; padding, bytes
// and text leave their bytes unread) and, in `record_size`, the bytes of one record.
// FormatError(name, offset, ...) for what it cannot read (titles, nested records,
// half floats, complex numbers, ...).
std::vector<NpyField> parse_npy_fields(std::string_view descr, const std::string& name, std::uint64_t offset,
                                       std::uint64_t& record_size);

}  // namespace vola::io
