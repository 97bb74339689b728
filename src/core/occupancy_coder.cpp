#include "occupancy_coder.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <type_traits>

#include "range_coder.hpp"
#include "vola/key.hpp"
#include "vola/error.hpp"

namespace vola {
VOLA_INLINE_NAMESPACE_BEGIN
namespace detail {

namespace {

using Cell = OccupancyCoder::Cell;

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
constexpr auto kOctantMask = make_octant_masks();

std::uint8_t octants_of(std::uint64_t word) noexcept {
  std::uint8_t m = 0;
  for (unsigned o = 0; o < 8; ++o)
    if (word & kOctantMask[o]) m = static_cast<std::uint8_t>(m | (1u << o));
  return m;
}

// Finds a block of the level by its coordinates. The blocks are in key order, so their
// keys are sorted, and a neighbour of block b is usually a few blocks before or after it:
// an exponential search from b, then a binary one, touches memory near b (a hash table
// of a few million blocks cost a cache miss per lookup, 1.7 us per voxel at depth 7).
class BlockIndex {
 public:
  explicit BlockIndex(std::span<const Cell> blocks) : keys_(blocks.size()) {
    for (std::size_t i = 0; i < blocks.size(); ++i) keys_[i] = encode(blocks[i].x, blocks[i].y, blocks[i].z);
  }
  // The index of the block at (x, y, z), or kNone; `near` = where to start looking.
  std::uint32_t find(std::uint32_t x, std::uint32_t y, std::uint32_t z, std::size_t near) const noexcept {
    if (((x | y | z) >> 20) != 0) return kNone;  // beyond any grid
    const Key key = encode(x, y, z);
    const std::size_t n = keys_.size();
    std::size_t lo, hi;  // the key is in [lo, hi) if anywhere
    if (keys_[near] < key) {
      std::size_t step = 1;
      lo = near + 1;
      while (lo + step <= n && keys_[lo + step - 1] < key) {
        lo += step;
        step *= 2;
      }
      hi = std::min(n, lo + step);
    } else {
      std::size_t step = 1;
      hi = near + 1;
      while (hi > step && keys_[hi - step - 1] >= key) {
        hi -= step;
        step *= 2;
      }
      lo = hi > step ? hi - step - 1 : 0;
    }
    const auto it = std::lower_bound(keys_.begin() + static_cast<std::ptrdiff_t>(lo),
                                     keys_.begin() + static_cast<std::ptrdiff_t>(hi), key);
    return it != keys_.end() && *it == key ? static_cast<std::uint32_t>(it - keys_.begin()) : kNone;
  }
  static constexpr std::uint32_t kNone = 0xFFFFFFFFu;

 private:
  std::vector<Key> keys_;
};

constexpr std::size_t kOctantContexts = 8 * 64 * 4 * 4;
constexpr std::size_t kCellContexts = 8 * 8 * 8 * 8 * 4 * 3;

// Both passes over one level; the encoder reads `words`, the decoder fills them (they
// start at 0). Every context reads only what the decoder has by then.
template <class Coder>
void code_level(Coder& coder, std::span<const Cell> blocks, std::span<std::uint64_t> words) {
  constexpr bool kEncoding = std::is_same_v<Coder, RangeEncoder>;
  const std::size_t n = blocks.size();
  const BlockIndex index(blocks);
  // Face neighbours of every block: -x, +x, -y, +y, -z, +z (kNone: no such block), and
  // the blocks below it along two or three axes (index = which axes: 3 xy, 5 xz, 6 yz,
  // 7 xyz; the others unused).
  std::vector<std::array<std::uint32_t, 6>> near(n);
  std::vector<std::array<std::uint32_t, 8>> lower(n);
  for (std::size_t b = 0; b < n; ++b) {
    const Cell c = blocks[b];
    near[b][0] = c.x ? index.find(c.x - 1, c.y, c.z, b) : BlockIndex::kNone;
    near[b][1] = index.find(c.x + 1, c.y, c.z, b);
    near[b][2] = c.y ? index.find(c.x, c.y - 1, c.z, b) : BlockIndex::kNone;
    near[b][3] = index.find(c.x, c.y + 1, c.z, b);
    near[b][4] = c.z ? index.find(c.x, c.y, c.z - 1, b) : BlockIndex::kNone;
    near[b][5] = index.find(c.x, c.y, c.z + 1, b);
    lower[b][0] = static_cast<std::uint32_t>(b);
    lower[b][1] = near[b][0];
    lower[b][2] = near[b][2];
    lower[b][4] = near[b][4];
    for (unsigned axes : {3u, 5u, 6u, 7u}) {
      const bool ok = (!(axes & 1u) || c.x) && (!(axes & 2u) || c.y) && (!(axes & 4u) || c.z);
      lower[b][axes] = ok ? index.find(c.x - (axes & 1u), c.y - ((axes >> 1) & 1u), c.z - ((axes >> 2) & 1u), b)
                          : BlockIndex::kNone;
    }
  }
  // A cell at or below (x, y, z) of block b, offsets -1 or 0 per axis: coded already.
  auto below_cell = [&](std::size_t b, std::uint64_t word, int x, int y, int z) -> unsigned {
    const unsigned axes = (x < 0 ? 1u : 0u) | (y < 0 ? 2u : 0u) | (z < 0 ? 4u : 0u);
    const unsigned bit = bit_of(static_cast<unsigned>(x & 3), static_cast<unsigned>(y & 3), static_cast<unsigned>(z & 3));
    if (axes == 0) return static_cast<unsigned>((word >> bit) & 1u);
    const std::uint32_t nb = lower[b][axes];
    return nb != BlockIndex::kNone ? static_cast<unsigned>((words[nb] >> bit) & 1u) : 0u;
  };

  // Pass A: octants.
  std::vector<std::uint8_t> octants(n, 0);
  std::vector<BitModel> octant_models(kOctantContexts);
  for (std::size_t b = 0; b < n; ++b) {
    const std::uint8_t actual = kEncoding ? octants_of(words[b]) : 0;
    unsigned mask = 0;
    for (unsigned o = 0; o < 8; ++o) {
      if (o == 7 && mask == 0) {  // a block is never empty
        mask = 0x80;
        break;
      }
      unsigned ctx = 0;
      for (unsigned a = 0; a < 3; ++a) {
        const unsigned axis_bit = 1u << a;
        const std::uint32_t below = near[b][2 * a], above = near[b][2 * a + 1];
        unsigned near_octant, far_block;
        if (!(o & axis_bit)) {  // lower half: the octant beyond, in the block below, is coded
          near_octant = below != BlockIndex::kNone ? (octants[below] >> (o | axis_bit)) & 1u : 0u;
        } else {  // upper half: the sibling below is coded
          near_octant = (mask >> (o ^ axis_bit)) & 1u;
        }
        far_block = above != BlockIndex::kNone ? 1u : 0u;
        ctx |= (near_octant | far_block << 1) << (2 * a);
      }
      const unsigned count = std::min<unsigned>(static_cast<unsigned>(std::popcount(mask)), 3u);
      // The same octant of the blocks below along x and y (two octants away).
      unsigned farther = 0;
      for (unsigned a = 0; a < 2; ++a) {
        const std::uint32_t nb = near[b][2 * a];
        farther |= (nb != BlockIndex::kNone ? (octants[nb] >> o) & 1u : 0u) << a;
      }
      BitModel& m = octant_models[o | ctx << 3 | count << 9 | farther << 11];
      if (coder.code(m, (actual >> o) & 1u)) mask |= 1u << o;
    }
    octants[b] = static_cast<std::uint8_t>(mask);
  }

  // Pass B: cells of the non-empty octants.
  std::vector<BitModel> cell_models(kCellContexts);
  for (std::size_t b = 0; b < n; ++b) {
    const std::uint64_t actual = kEncoding ? words[b] : 0;
    std::uint64_t word = 0;
    for (unsigned o = 0; o < 8; ++o) {
      if (!((octants[b] >> o) & 1u)) continue;
      // The octant beyond this one along each axis (in this block or the next one).
      unsigned beyond = 0;
      for (unsigned a = 0; a < 3; ++a) {
        const unsigned axis_bit = 1u << a;
        unsigned occupied;
        if (!(o & axis_bit)) {
          occupied = (octants[b] >> (o | axis_bit)) & 1u;
        } else {
          const std::uint32_t above = near[b][2 * a + 1];
          occupied = above != BlockIndex::kNone ? (octants[above] >> (o ^ axis_bit)) & 1u : 0u;
        }
        beyond |= occupied << a;
      }
      unsigned set = 0;
      for (unsigned c = 0; c < 8; ++c) {
        const unsigned p[3] = {2 * (o & 1u) + (c & 1u), 2 * ((o >> 1) & 1u) + ((c >> 1) & 1u),
                               2 * (o >> 2) + (c >> 2)};
        const unsigned bit = bit_of(p[0], p[1], p[2]);
        if (c == 7 && set == 0) {  // an octant of pass B is never empty
          word |= std::uint64_t{1} << bit;
          break;
        }
        const int x = static_cast<int>(p[0]), y = static_cast<int>(p[1]), z = static_cast<int>(p[2]);
        const unsigned below = below_cell(b, word, x - 1, y, z) | below_cell(b, word, x, y - 1, z) << 1 |
                               below_cell(b, word, x, y, z - 1) << 2;
        const unsigned diagonal = below_cell(b, word, x - 1, y - 1, z) | below_cell(b, word, x - 1, y, z - 1) << 1 |
                                  below_cell(b, word, x, y - 1, z - 1) << 2;
        const unsigned farther = below_cell(b, word, x - 2, y, z) | below_cell(b, word, x, y - 2, z) << 1;
        BitModel& m = cell_models[c | below << 3 | beyond << 6 | diagonal << 9 | farther << 12 | std::min(set, 2u) << 14];
        if (coder.code(m, (actual >> bit) & 1u)) {
          word |= std::uint64_t{1} << bit;
          ++set;
        }
      }
    }
    if constexpr (!kEncoding) words[b] = word;
  }
}

}  // namespace

OccupancyCoder::OccupancyCoder() : blocks_{Cell{0, 0, 0}} {}

void OccupancyCoder::advance(std::span<const std::uint64_t> words, bool last) {
  std::vector<Cell> next;
  if (!last) {
    std::uint64_t cells = 0;
    for (std::uint64_t w : words) cells += static_cast<std::uint64_t>(std::popcount(w));
    next.reserve(cells);
    for (std::size_t b = 0; b < words.size(); ++b) {
      std::uint64_t w = words[b];
      const Cell c = blocks_[b];
      while (w) {
        const unsigned i = static_cast<unsigned>(std::countr_zero(w));
        w &= w - 1;
        next.push_back({4 * c.x + (i & 3u), 4 * c.y + ((i >> 2) & 3u), 4 * c.z + (i >> 4)});
      }
    }
  }
  blocks_ = std::move(next);
}

std::vector<std::uint8_t> OccupancyCoder::encode(std::span<const std::uint64_t> words, bool last) {
  if (words.size() != blocks_.size())
    VOLA_THROW(Error("occupancy coder: the level has " + std::to_string(words.size()) + " words, the level above " +
                     std::to_string(blocks_.size()) + " cells"));
  for (std::uint64_t w : words)
    if (w == 0 && blocks_.size() > 1) VOLA_THROW(Error("occupancy coder: an empty block below the root"));
  std::vector<std::uint8_t> out;
  RangeEncoder coder(out);
  if (blocks_.size() == 1 && words[0] == 0) {
    // The root of an empty tree: the one word that may be 0 (the passes assume none is).
    std::vector<BitModel> flag(1);
    coder.code(flag[0], true);
  } else {
    if (blocks_.size() == 1) {
      std::vector<BitModel> flag(1);
      coder.code(flag[0], false);
    }
    std::vector<std::uint64_t> copy(words.begin(), words.end());
    code_level(coder, blocks_, std::span<std::uint64_t>(copy));
  }
  coder.finish();
  advance(words, last);
  return out;
}

void OccupancyCoder::decode(std::span<const std::uint8_t> stream, std::span<std::uint64_t> words, bool last,
                            const std::string& name, std::uint64_t offset) {
  if (words.size() != blocks_.size())
    VOLA_THROW(FormatError(name, offset, "occupancy level of " + std::to_string(words.size()) +
                                             " words below a level of " + std::to_string(blocks_.size()) + " cells"));
  if (blocks_.size() > 0xFFFFFFFEu)
    VOLA_THROW(FormatError(name, offset, "an occupancy level of 2^32 blocks or more"));
  if (stream.empty() || stream[0] != 0)  // the encoder's first byte is always 0
    VOLA_THROW(FormatError(name, offset, "the coded occupancy level is corrupt (it does not start with a 0 byte)"));
  std::fill(words.begin(), words.end(), 0);
  RangeDecoder coder(stream);
  bool empty_root = false;
  if (blocks_.size() == 1) {
    std::vector<BitModel> flag(1);
    empty_root = coder.code(flag[0]);
  }
  if (!empty_root) code_level(coder, blocks_, words);
  if (!coder.consumed_exactly())
    VOLA_THROW(FormatError(name, offset, "the coded occupancy level is corrupt (it does not decode to its own " +
                                             std::to_string(stream.size()) + " bytes)"));
  advance(words, last);
}

}  // namespace detail
VOLA_INLINE_NAMESPACE_END
}  // namespace vola
