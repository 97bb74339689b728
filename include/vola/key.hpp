// VOLA keys: one integer that says where a voxel (or a coarser node) is.
//
// A key holds one 6-bit digit per level, level 0 in the most significant digit.
// The digit of level L is the voxel's cell inside its level-L block:
//     digit = (x & 3) + 4 * (y & 3) + 16 * (z & 3)   of the level-L cell coordinates.
// Because the 2-bit groups of x, y and z sit at fixed places whatever the depth,
// encoding is depth independent: key(x,y,z) = spread(x) | spread(y) << 2 | spread(z) << 4,
// where spread() moves bit pair j of a coordinate to bits 6j, 6j+1.
// Sorting keys sorts voxels in exactly the order a sparse VOLA file stores them.
#pragma once

#include <array>
#include <cstdint>

#include "vola/version.hpp"

namespace vola {
VOLA_INLINE_NAMESPACE_BEGIN

using Key = std::uint64_t;

inline constexpr int kMinDepth = 1;
inline constexpr int kMaxDepth = 10;

// Voxels per axis at `depth`: 4^depth.
constexpr std::uint32_t side_of(int depth) noexcept { return std::uint32_t{1} << (2 * depth); }

struct Voxel {
  std::uint32_t x = 0, y = 0, z = 0;
  friend constexpr bool operator==(const Voxel&, const Voxel&) = default;
};

namespace detail {
// spread_table[c]: the 5 bit pairs of a 10-bit value c moved to bits 6j, 6j+1 (j = 0..4).
// 4 KiB, so that a coordinate (20 bits at depth 10) spreads with two lookups: encoding
// is on the path of every lookup and build.
constexpr std::array<std::uint32_t, 1024> make_spread_table() {
  std::array<std::uint32_t, 1024> t{};
  for (std::uint32_t c = 0; c < 1024; ++c) {
    std::uint32_t v = 0;
    for (int j = 0; j < 5; ++j) v |= ((c >> (2 * j)) & 3u) << (6 * j);
    t[c] = v;
  }
  return t;
}
alignas(64) inline constexpr auto spread_table = make_spread_table();

// compact_table[d]: inverse of spread for one 12-bit run of two digits
// (x, y, z bit pairs of two levels) -> 4 bits of x | 4 bits of y << 4 | 4 bits of z << 8.
constexpr std::array<std::uint16_t, 4096> make_compact_table() {
  std::array<std::uint16_t, 4096> t{};
  for (std::uint32_t d = 0; d < 4096; ++d) {
    std::uint32_t x = 0, y = 0, z = 0;
    for (int j = 0; j < 2; ++j) {
      const std::uint32_t digit = (d >> (6 * j)) & 63u;
      x |= (digit & 3u) << (2 * j);
      y |= ((digit >> 2) & 3u) << (2 * j);
      z |= ((digit >> 4) & 3u) << (2 * j);
    }
    t[d] = static_cast<std::uint16_t>(x | (y << 4) | (z << 8));
  }
  return t;
}
inline constexpr auto compact_table = make_compact_table();

// Bits 20 and up of c are ignored.
constexpr Key spread(std::uint32_t c) noexcept {
  return Key{spread_table[c & 1023u]} | (Key{spread_table[(c >> 10) & 1023u]} << 30);
}
}  // namespace detail

// Key of voxel (x, y, z); coordinates must be < 4^10.
constexpr Key encode(std::uint32_t x, std::uint32_t y, std::uint32_t z) noexcept {
  return detail::spread(x) | (detail::spread(y) << 2) | (detail::spread(z) << 4);
}
constexpr Key encode(Voxel v) noexcept { return encode(v.x, v.y, v.z); }

constexpr Voxel decode(Key key) noexcept {
  Voxel v;
  for (int chunk = 0; chunk < 5; ++chunk) {  // 5 chunks of 12 bits = 10 digits
    const std::uint32_t c = detail::compact_table[(key >> (12 * chunk)) & 4095u];
    v.x |= (c & 15u) << (4 * chunk);
    v.y |= ((c >> 4) & 15u) << (4 * chunk);
    v.z |= ((c >> 8) & 15u) << (4 * chunk);
  }
  return v;
}

// Digit of `level` (0 = root) in a key of a depth-`depth` voxel: the bit index of the
// voxel's level-`level` cell inside its block.
constexpr unsigned digit(Key key, int level, int depth) noexcept {
  return static_cast<unsigned>(key >> (6 * (depth - 1 - level))) & 63u;
}

// The key of the node at `level` (the first `level`+1 digits) holding a depth-`depth` key;
// it is itself the key of a voxel of a depth-(level+1) tree.
constexpr Key node_at(Key key, int level, int depth) noexcept {
  return key >> (6 * (depth - 1 - level));
}

// Bit index of local (x, y, z) in 0..3 inside one 64-bit block.
constexpr unsigned bit_index(unsigned x, unsigned y, unsigned z) noexcept { return x + 4 * y + 16 * z; }

VOLA_INLINE_NAMESPACE_END
}  // namespace vola
