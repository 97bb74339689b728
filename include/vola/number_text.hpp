// Doubles as text for files and listings that people read and programs parse back.
#pragma once

#include <charconv>
#include <cmath>

namespace vola {

// Room for any double write_number writes.
inline constexpr int kNumberTextSize = 48;

// The shortest text that reads back as the same double, written into [first, first +
// kNumberTextSize) and returning its end: positional between 1e-4 and 1e16, as Python's
// repr writes it ("5000000", not to_chars' "5e+06": a UTM northing), scientific outside
// ("1e-09", "1e+300"); "nan", "inf" and "-inf" as to_chars writes them.
inline char* write_number(char* first, double value) {
  const double magnitude = std::fabs(value);
  const bool scientific = magnitude != 0.0 && (magnitude < 1e-4 || magnitude >= 1e16);
  return scientific || !std::isfinite(value)
             ? std::to_chars(first, first + kNumberTextSize, value).ptr
             : std::to_chars(first, first + kNumberTextSize, value, std::chars_format::fixed).ptr;
}

}  // namespace vola
