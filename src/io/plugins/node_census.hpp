// How many nodes a library's tree would make for a set of voxels, counted before it is
// built: OpenVDB's internal nodes take 33 KiB and 264 KiB each, so 10^6 voxels scattered
// over a wide grid make a tree of tens of gigabytes (measured: `vola export` of 10^6
// uniform voxels at depth 10 reached 24 GB before the kernel killed it). One sort of the
// voxels' Morton codes gives the node count of every level at once: a cell of 2^s voxels
// per axis is a run of codes equal above bit 3s.
#pragma once

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

namespace vola::io {

// Coordinates of up to 21 bits per axis, interleaved into 63 bits.
inline std::uint64_t morton_code(std::uint32_t x, std::uint32_t y, std::uint32_t z) noexcept {
  const auto spread = [](std::uint64_t v) {
    std::uint64_t out = 0;
    for (int bit = 0; bit < 21; ++bit) out |= ((v >> bit) & 1u) << (3 * bit);
    return out;
  };
  return spread(x) | spread(y) << 1 | spread(z) << 2;
}

// For each shift s in `shifts` (each < 21): the number of distinct cells (x >> s, y >> s,
// z >> s) the codes fall in. Sorts `codes`.
inline std::vector<std::uint64_t> cells_per_shift(std::vector<std::uint64_t>& codes, const std::vector<int>& shifts) {
  std::sort(codes.begin(), codes.end());
  std::vector<std::uint64_t> counts(shifts.size(), codes.empty() ? 0 : 1);
  for (std::size_t n = 1; n < codes.size(); ++n) {
    const std::uint64_t differ = codes[n] ^ codes[n - 1];
    if (differ == 0) continue;
    for (std::size_t s = 0; s < shifts.size(); ++s)
      if (differ >> (3 * shifts[s])) ++counts[s];
  }
  return counts;
}

// Bytes as GiB with one decimal, for the refusals.
inline std::string gib_text(std::uint64_t bytes) {
  char text[32];
  std::snprintf(text, sizeof text, "%.1f", static_cast<double>(bytes) / (1u << 30));
  return text;
}

}  // namespace vola::io
