// Internal to the NPY reader: the fields of a structured dtype (src/io/npy_records.cpp).
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "vola/io/npy.hpp"

namespace vola::io {

// numpy's descr list ("[('x', '<f8'), ('rgb', '|u1', (3,)), ...]", from its '[' on): the
// numeric fields with their offsets (subarrays as one field per element; padding, bytes
// and text leave their bytes unread) and, in `record_size`, the bytes of one record.
// FormatError(name, offset, ...) for what it cannot read (titles, nested records,
// half floats, complex numbers, ...).
std::vector<NpyField> parse_npy_fields(std::string_view descr, const std::string& name, std::uint64_t offset,
                                       std::uint64_t& record_size);

}  // namespace vola::io
