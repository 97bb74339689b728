#include "occupancy_coder.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <type_traits>

#include "occupancy_geometry.hpp"
#include "occupancy_mixed.hpp"
#include "range_coder.hpp"
#include "vola/error.hpp"

namespace vola {
VOLA_INLINE_NAMESPACE_BEGIN
namespace detail {

namespace {

using Neighbours = OccupancyCoder::Neighbours;
constexpr std::uint32_t kNoBlock = OccupancyCoder::kNoBlock;

constexpr std::size_t kOctantContexts = 8 * 64 * 4 * 4;
constexpr std::size_t kCellContexts = 8 * 8 * 8 * 8 * 4 * 3;

// Both passes over one level; the encoder reads `words`, the decoder fills them (they
// start at 0). Every context reads only what the decoder has by then. `near`: each
// block's neighbours (advance() derives them from the level above).
template <class Coder>
void code_level(Coder& coder, std::span<const Neighbours> near, std::span<std::uint64_t> words) {
  constexpr bool kEncoding = std::is_same_v<Coder, RangeEncoder>;
  const std::size_t n = near.size();
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
        const std::uint32_t below = near[b].block[2 * a], above = near[b].block[2 * a + 1];
        unsigned near_octant, far_block;
        if (!(o & axis_bit)) {  // lower half: the octant beyond, in the block below, is coded
          near_octant = below != kNoBlock ? (octants[below] >> (o | axis_bit)) & 1u : 0u;
        } else {  // upper half: the sibling below is coded
          near_octant = (mask >> (o ^ axis_bit)) & 1u;
        }
        far_block = above != kNoBlock ? 1u : 0u;
        ctx |= (near_octant | far_block << 1) << (2 * a);
      }
      const unsigned count = std::min<unsigned>(static_cast<unsigned>(std::popcount(mask)), 3u);
      // The same octant of the blocks below along x and y (two octants away).
      unsigned farther = 0;
      for (unsigned a = 0; a < 2; ++a) {
        const std::uint32_t nb = near[b].block[2 * a];
        farther |= (nb != kNoBlock ? (octants[nb] >> o) & 1u : 0u) << a;
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
    // The words of the blocks below along each set of axes (bit 0 x, 1 y, 2 z; 0 where
    // there is no such block), coded already: a cell's context reads them without a
    // branch. Entry 0 is this block's own word so far.
    std::array<std::uint64_t, 8> below_words{};
    for (unsigned axes = 1; axes < 7; ++axes) {
      const std::uint32_t nb = near[b].block[kLowerDirection[axes]];
      below_words[axes] = nb != kNoBlock ? words[nb] : 0;
    }
    // The cell at (x, y, z) with offsets of -1 or 0 per axis from this block (-2 along x
    // or y alone): coded already.
    const auto below_cell = [&](int x, int y, int z) -> unsigned {
      const unsigned axes = (x < 0 ? 1u : 0u) | (y < 0 ? 2u : 0u) | (z < 0 ? 4u : 0u);
      const unsigned bit = bit_of(static_cast<unsigned>(x & 3), static_cast<unsigned>(y & 3), static_cast<unsigned>(z & 3));
      return static_cast<unsigned>(((axes ? below_words[axes] : word) >> bit) & 1u);
    };
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
          const std::uint32_t above = near[b].block[2 * a + 1];
          occupied = above != kNoBlock ? (octants[above] >> (o ^ axis_bit)) & 1u : 0u;
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
        const unsigned below = below_cell(x - 1, y, z) | below_cell(x, y - 1, z) << 1 | below_cell(x, y, z - 1) << 2;
        const unsigned diagonal =
            below_cell(x - 1, y - 1, z) | below_cell(x - 1, y, z - 1) << 1 | below_cell(x, y - 1, z - 1) << 2;
        const unsigned farther = below_cell(x - 2, y, z) | below_cell(x, y - 2, z) << 1;
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

OccupancyCoder::OccupancyCoder(Modelling modelling) : modelling_(modelling), near_(1) {
  near_[0].block.fill(kNoBlock);
}

void OccupancyCoder::advance(std::span<const std::uint64_t> words, bool last) {
  std::vector<Neighbours> next;
  if (!last) {
    // first[p]: the index of parent p's first child.
    std::vector<std::uint64_t> first(words.size() + 1, 0);
    for (std::size_t p = 0; p < words.size(); ++p)
      first[p + 1] = first[p] + static_cast<std::uint64_t>(std::popcount(words[p]));
    if (first.back() > 0xFFFFFFFEu) VOLA_THROW(Error("occupancy coder: a level of 2^32 blocks or more"));
    next.resize(first.back());
    std::size_t child = 0;
    for (std::size_t p = 0; p < words.size(); ++p) {
      std::uint64_t w = words[p];
      while (w) {
        const auto i = static_cast<unsigned>(std::countr_zero(w));
        w &= w - 1;
        const int x = static_cast<int>(i & 3u), y = static_cast<int>((i >> 2) & 3u), z = static_cast<int>(i >> 4);
        Neighbours& out = next[child++];
        out.block[9] = kNoBlock;
        for (unsigned d = 0; d < 9; ++d) {
          const int nx = x + kDirection[d][0], ny = y + kDirection[d][1], nz = z + kDirection[d][2];
          // The parent holding the neighbour: this one, or its neighbour across the edge crossed.
          const unsigned across = direction_of(nx < 0 ? -1 : (nx > 3 ? 1 : 0), ny < 0 ? -1 : (ny > 3 ? 1 : 0),
                                               nz < 0 ? -1 : (nz > 3 ? 1 : 0));
          const std::uint32_t parent = across == 9 ? static_cast<std::uint32_t>(p) : near_[p].block[across];
          if (parent == kNoBlock) {
            out.block[d] = kNoBlock;
            continue;
          }
          const unsigned bit = bit_of(static_cast<unsigned>(nx & 3), static_cast<unsigned>(ny & 3),
                                      static_cast<unsigned>(nz & 3));
          const std::uint64_t pw = words[parent];
          out.block[d] = (pw >> bit) & 1u ? static_cast<std::uint32_t>(
                                                first[parent] + static_cast<std::uint64_t>(std::popcount(
                                                                    pw & ((std::uint64_t{1} << bit) - 1))))
                                          : kNoBlock;
        }
      }
    }
  }
  near_ = std::move(next);
}

std::vector<std::uint8_t> OccupancyCoder::encode(std::span<const std::uint64_t> words, bool last) {
  if (words.size() != near_.size())
    VOLA_THROW(Error("occupancy coder: the level has " + std::to_string(words.size()) + " words, the level above " +
                     std::to_string(near_.size()) + " cells"));
  for (std::uint64_t w : words)
    if (w == 0 && near_.size() > 1) VOLA_THROW(Error("occupancy coder: an empty block below the root"));
  std::vector<std::uint8_t> out;
  RangeEncoder coder(out);
  if (near_.size() == 1 && words[0] == 0) {
    // The root of an empty tree: the one word that may be 0 (the passes assume none is).
    std::vector<BitModel> flag(1);
    coder.code(flag[0], true);
  } else {
    if (near_.size() == 1) {
      std::vector<BitModel> flag(1);
      coder.code(flag[0], false);
    }
    std::vector<std::uint64_t> copy(words.begin(), words.end());
    if (modelling_ == Modelling::mixed)
      encode_level_mixed(coder, std::span<const Neighbours>(near_), std::span<std::uint64_t>(copy));
    else
      code_level(coder, std::span<const Neighbours>(near_), std::span<std::uint64_t>(copy));
  }
  coder.finish();
  advance(words, last);
  return out;
}

void OccupancyCoder::decode(std::span<const std::uint8_t> stream, std::span<std::uint64_t> words, bool last,
                            std::uint64_t next_words, const std::string& name, std::uint64_t offset) {
  if (words.size() != near_.size())
    VOLA_THROW(FormatError(name, offset, "occupancy level of " + std::to_string(words.size()) +
                                             " words below a level of " + std::to_string(near_.size()) + " cells"));
  if (near_.size() > 0xFFFFFFFEu)
    VOLA_THROW(FormatError(name, offset, "an occupancy level of 2^32 blocks or more"));
  if (stream.empty() || stream[0] != 0)  // the encoder's first byte is always 0
    VOLA_THROW(FormatError(name, offset, "the coded occupancy level is corrupt (it does not start with a 0 byte)"));
  std::fill(words.begin(), words.end(), 0);
  RangeDecoder coder(stream);
  bool empty_root = false;
  if (near_.size() == 1) {
    std::vector<BitModel> flag(1);
    empty_root = coder.code(flag[0]);
  }
  if (!empty_root) {
    if (modelling_ == Modelling::mixed)
      decode_level_mixed(coder, std::span<const Neighbours>(near_), words);
    else
      code_level(coder, std::span<const Neighbours>(near_), words);
  }
  if (!coder.consumed_exactly())
    VOLA_THROW(FormatError(name, offset, "the coded occupancy level is corrupt (it does not decode to its own " +
                                             std::to_string(stream.size()) + " bytes)"));
  if (!last) {
    std::uint64_t cells = 0;
    for (std::uint64_t w : words) cells += static_cast<std::uint64_t>(std::popcount(w));
    if (cells != next_words)
      VOLA_THROW(FormatError(name, offset, "occupancy level with " + std::to_string(cells) + " cells above a level of " +
                                               std::to_string(next_words) + " words"));
  }
  advance(words, last);
}

}  // namespace detail
VOLA_INLINE_NAMESPACE_END
}  // namespace vola
