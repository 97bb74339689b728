// Internal: cells, octants and neighbour directions of a block, shared by the two
// occupancy coders (occupancy_coder.cpp: levels flags 3; occupancy_mixed.cpp: flags 4).
#pragma once

#include <array>
#include <cstdint>

#include "vola/version.hpp"

namespace vola {
VOLA_INLINE_NAMESPACE_BEGIN
namespace detail {

// Bit of cell (x, y, z) of a block: x + 4y + 16z.
constexpr unsigned bit_of(unsigned x, unsigned y, unsigned z) noexcept { return x + 4 * y + 16 * z; }

// The cells of octant o (bit 0: upper x half, bit 1: y, bit 2: z) as a word mask.
constexpr std::array<std::uint64_t, 8> make_octant_masks() {
  std::array<std::uint64_t, 8> m{};
  for (unsigned o = 0; o < 8; ++o)
    for (unsigned c = 0; c < 8; ++c) {
      const unsigned x = 2 * (o & 1u) + (c & 1u), y = 2 * ((o >> 1) & 1u) + ((c >> 1) & 1u),
                     z = 2 * (o >> 2) + (c >> 2);
      m[o] |= std::uint64_t{1} << bit_of(x, y, z);
    }
  return m;
}
inline constexpr auto kOctantMask = make_octant_masks();

inline std::uint8_t octants_of(std::uint64_t word) noexcept {
  std::uint8_t m = 0;
  for (unsigned o = 0; o < 8; ++o)
    if (word & kOctantMask[o]) m = static_cast<std::uint8_t>(m | (1u << o));
  return m;
}

// The directions of OccupancyCoder::Neighbours::block: the six faces, then the three
// lower edges.
inline constexpr int kDirection[9][3] = {{-1, 0, 0}, {1, 0, 0},   {0, -1, 0},  {0, 1, 0}, {0, 0, -1},
                                         {0, 0, 1},  {-1, -1, 0}, {-1, 0, -1}, {0, -1, -1}};
// The directions whose blocks come before a block in file order, so that every one of
// their cells is coded when the block is: -x, -y, -z and the three lower edges.
inline constexpr std::array<unsigned, 6> kEarlierDirections = {0, 2, 4, 6, 7, 8};
// The direction (index into kDirection, 9 = the block itself) of the block below along
// the axes of `axes` (bit 0 x, 1 y, 2 z); 7 (all three) is never asked for.
inline constexpr unsigned kLowerDirection[8] = {9, 0, 2, 6, 4, 7, 8, 9};
// The direction index of an offset with components in {-1, 0, 1} that is one of them (or 9).
constexpr unsigned direction_of(int dx, int dy, int dz) noexcept {
  for (unsigned d = 0; d < 9; ++d)
    if (kDirection[d][0] == dx && kDirection[d][1] == dy && kDirection[d][2] == dz) return d;
  return 9;
}

}  // namespace detail
VOLA_INLINE_NAMESPACE_END
}  // namespace vola
