#include "occupancy_mixed.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <memory>
#include <type_traits>
#include <vector>

#include "logistic_mixing.hpp"
#include "occupancy_geometry.hpp"

namespace vola {
VOLA_INLINE_NAMESPACE_BEGIN
namespace detail {

namespace {

using Neighbours = OccupancyCoder::Neighbours;

// One bit's prediction: K context models (each a table of BitModels, indexed by the
// context's value), mixed, then refined. Fresh for every level.
template <int K, int Sets, int MapContexts, unsigned kMaxShift>
class MixedBit {
 public:
  explicit MixedBit(const std::array<unsigned, K>& context_bits) {
    for (int k = 0; k < K; ++k) tables_[k].resize(std::size_t{1} << context_bits[k]);
  }
  // Codes (or decodes) one bit given each model's context, the mixer's weight set and the
  // map's context.
  template <class Coder>
  bool code(Coder& coder, bool bit, const std::array<unsigned, K>& contexts, unsigned set, unsigned map_context) {
    std::array<int, K> logits;
    for (int k = 0; k < K; ++k) {
      models_[k] = &tables_[k][contexts[k]];
      logits[k] = logit_of(*models_[k]);
    }
    const int mixed = mixer_.mix(logits, set);
    const int p1 = squash(mixed);
    const int refined = map_.refine(mixed, map_context);
    bit = coder.code_with(zero_probability(p1, refined), bit);
    mixer_.update(bit, p1);
    map_.update(bit);
    for (int k = 0; k < K; ++k) models_[k]->template update<kMaxShift>(bit);
    return bit;
  }

 private:
  std::array<std::vector<BitModel>, K> tables_;
  std::array<BitModel*, K> models_{};
  Mixer<K, Sets> mixer_;
  ProbabilityMap<MapContexts> map_;
};

// What the decoder has around a block: its cells (N per side: 2 for octants, 4 for
// cells; bit x + Ny + N^2 z of a block's value) coded so far, and those of the blocks
// before it in file order (kEarlierDirections), as rows along x over coordinates from
// -N (Ys rows along y, Zs along z); everything else reads 0.
template <int N, class Row, std::size_t Ys, std::size_t Zs>
class Window {
 public:
  template <class Values>
  void load(const Neighbours& near, const Values& values) {
    for (auto& plane : rows_) plane.fill(0);
    for (unsigned d : kEarlierDirections) {
      const std::uint32_t nb = near.block[d];
      if (nb == OccupancyCoder::kNoBlock) continue;
      const std::uint64_t v = values[nb];
      for (int y = 0; y < N; ++y)
        for (int z = 0; z < N; ++z)
          row_at(y + N * kDirection[d][1], z + N * kDirection[d][2]) |=
              static_cast<Row>(((v >> (N * y + N * N * z)) & ((1u << N) - 1)) << (N + N * kDirection[d][0]));
    }
  }
  void set(int x, int y, int z) noexcept { row_at(y, z) |= static_cast<Row>(1u << (x + N)); }
  unsigned at(int x, int y, int z) const noexcept { return (row(y, z) >> (x + N)) & 1u; }
  // Row (y, z) as bits: bit i is x = i - N.
  unsigned row(int y, int z) const noexcept { return rows_[static_cast<std::size_t>(y + N)][static_cast<std::size_t>(z + N)]; }

 private:
  Row& row_at(int y, int z) noexcept { return rows_[static_cast<std::size_t>(y + N)][static_cast<std::size_t>(z + N)]; }
  std::array<std::array<Row, Zs>, Ys> rows_{};
};
// Octants: x -2..3, y -2..1, z -2..2; cells: x -4..9, y -4..3, z -4..5.
using OctantWindow = Window<2, std::uint8_t, 4, 5>;
using CellWindow = Window<4, std::uint16_t, 8, 10>;

// Pass A: which octants of every block hold anything.
constexpr int kOctantModels = 5;
using OctantBit = MixedBit<kOctantModels, 32, 256, 5>;

template <class Coder>
void code_octants(Coder& coder, std::span<const Neighbours> near, std::span<const std::uint64_t> words,
                  std::span<std::uint8_t> octants) {
  constexpr bool kEncoding = std::is_same_v<Coder, RangeEncoder>;
  auto bit = std::make_unique<OctantBit>(std::array<unsigned, kOctantModels>{13, 16, 14, 14, 16});
  OctantWindow window;
  for (std::size_t b = 0; b < near.size(); ++b) {
    const unsigned actual = kEncoding ? octants_of(words[b]) : 0u;
    window.load(near[b], octants);
    unsigned exist = 0;
    for (unsigned d = 0; d < 9; ++d) exist |= (near[b].block[d] != OccupancyCoder::kNoBlock ? 1u : 0u) << d;
    unsigned mask = 0;
    for (unsigned o = 0; o < 8; ++o) {
      if (o == 7 && mask == 0) {  // a block is never empty
        mask = 0x80;
        break;
      }
      const int x = static_cast<int>(o & 1u), y = static_cast<int>((o >> 1) & 1u), z = static_cast<int>(o >> 2);
      // The octants next to o on the lower side along each axis, and whether the block
      // above along it exists.
      unsigned faces = 0;
      for (unsigned a = 0; a < 3; ++a) {
        const unsigned lower = window.at(x - (a == 0), y - (a == 1), z - (a == 2));
        const unsigned above = near[b].block[2 * a + 1] != OccupancyCoder::kNoBlock ? 1u : 0u;
        faces |= (lower | above << 1) << (2 * a);
      }
      const unsigned count = std::min<unsigned>(static_cast<unsigned>(std::popcount(mask)), 3u);
      const unsigned farther = window.at(x - 2, y, z) | window.at(x, y - 2, z) << 1;
      const unsigned before_x = window.at(x - 1, y, z - 1) | window.at(x - 1, y, z) << 1 | window.at(x - 1, y, z + 1) << 2;
      const unsigned before_y = window.at(x, y - 1, z - 1) | window.at(x, y - 1, z) << 1 | window.at(x, y - 1, z + 1) << 2;
      const unsigned under = window.at(x, y, z - 1);
      // Octants set within two along x, two back along y and one along z, of those coded.
      unsigned around = 0;
      for (int dz = -1; dz <= 1; ++dz) {
        around += static_cast<unsigned>(std::popcount(static_cast<unsigned>(window.row(y, z + dz) >> x) & 3u));
        for (int dy = -2; dy <= -1; ++dy)
          around += static_cast<unsigned>(std::popcount(static_cast<unsigned>(window.row(y + dy, z + dz) >> x) & 31u));
      }
      const std::array<unsigned, kOctantModels> contexts = {
          o | faces << 3 | count << 9 | farther << 11,
          before_x | before_y << 3 | under << 6 | window.at(x - 1, y - 1, z) << 7 | window.at(x + 1, y - 1, z) << 8 |
              farther << 9 | o << 11 | count << 14,
          exist | o << 9 | count << 12,
          (mask | 1u << o) | (exist & 0x3Fu) << 8,  // mask < 2^o: one code per (o, mask)
          std::min(around, 15u) | o << 4 | count << 7 | under << 9 | (exist & 0x3Fu) << 10};
      const unsigned map_context = o | count << 3 | under << 5 | window.at(x - 1, y, z) << 6 | window.at(x, y - 1, z) << 7;
      if (bit->code(coder, (actual >> o) & 1u, contexts, o | count << 3, map_context)) {
        mask |= 1u << o;
        window.set(x, y, z);
      }
    }
    octants[b] = static_cast<std::uint8_t>(mask);
  }
}

// Pass B: the cells of the set octants, column by column.
constexpr int kCellModels = 6;
using CellBit = MixedBit<kCellModels, 16, 256, 4>;

template <class Coder>
void code_cells(Coder& coder, std::span<const Neighbours> near, std::span<std::uint64_t> words,
                std::span<const std::uint8_t> octants) {
  constexpr bool kEncoding = std::is_same_v<Coder, RangeEncoder>;
  auto bit = std::make_unique<CellBit>(std::array<unsigned, kCellModels>{18, 15, 16, 16, 15, 16});
  CellWindow window;
  for (std::size_t b = 0; b < near.size(); ++b) {
    const std::uint64_t actual = kEncoding ? words[b] : 0;
    const unsigned block_octants = octants[b];
    window.load(near[b], words);
    // The octant beyond each octant along x, y and z (in this block or the one above).
    std::array<unsigned, 8> beyond{};
    for (unsigned o = 0; o < 8; ++o)
      for (unsigned a = 0; a < 3; ++a) {
        const unsigned axis_bit = 1u << a;
        unsigned occupied;
        if (!(o & axis_bit)) {
          occupied = (block_octants >> (o | axis_bit)) & 1u;
        } else {
          const std::uint32_t above = near[b].block[2 * a + 1];
          occupied = above != OccupancyCoder::kNoBlock ? (octants[above] >> (o ^ axis_bit)) & 1u : 0u;
        }
        beyond[o] |= occupied << a;
      }
    std::array<unsigned, 8> set_in{}, left_in{};
    left_in.fill(8);
    std::uint64_t word = 0;
    for (int y = 0; y < 4; ++y)
      for (int x = 0; x < 4; ++x)
        for (int z = 0; z < 4; ++z) {
          const unsigned o = static_cast<unsigned>(x >> 1) | static_cast<unsigned>(y >> 1) << 1 |
                             static_cast<unsigned>(z >> 1) << 2;
          if (!((block_octants >> o) & 1u)) continue;
          const unsigned cell_bit = bit_of(static_cast<unsigned>(x), static_cast<unsigned>(y), static_cast<unsigned>(z));
          const bool last = --left_in[o] == 0;
          if (last && set_in[o] == 0) {  // an octant of pass B is never empty
            word |= std::uint64_t{1} << cell_bit;
            window.set(x, y, z);
            continue;
          }
          const unsigned set = std::min(set_in[o], 2u), is_last = last ? 1u : 0u, near_beyond = beyond[o];
          const unsigned before_x = window.at(x - 1, y, z - 1) | window.at(x - 1, y, z) << 1 | window.at(x - 1, y, z + 1) << 2;
          const unsigned before_y = window.at(x, y - 1, z - 1) | window.at(x, y - 1, z) << 1 | window.at(x, y - 1, z + 1) << 2;
          const unsigned under = window.at(x, y, z - 1);
          const unsigned diagonal = window.at(x - 1, y - 1, z) | window.at(x + 1, y - 1, z) << 1;
          const unsigned farther = window.at(x - 2, y, z) | window.at(x, y - 2, z) << 1;
          // Cells set within two along z in the three columns before along x, along y,
          // and in five columns of the rows before diagonally.
          unsigned along_x = 0, along_y = 0, diagonals = 0;
          for (int dz = -2; dz <= 2; ++dz) {
            along_x += static_cast<unsigned>(std::popcount((window.row(y, z + dz) >> (x + 1)) & 7u));
            for (int dy = 1; dy <= 3; ++dy) along_y += window.at(x, y - dy, z + dz);
            // Row y-1: x-2, x-1, x+1, x+2 (bits x+2, x+3, x+5, x+6); row y-2: x-1.
            diagonals += static_cast<unsigned>(std::popcount((window.row(y - 1, z + dz) >> (x + 2)) & 0x1Bu)) +
                         window.at(x - 1, y - 2, z + dz);
          }
          const unsigned middle_x = (before_x >> 1) & 1u, middle_y = (before_y >> 1) & 1u;
          const unsigned pattern = before_x | before_y << 3 | under << 6 | diagonal << 7 | farther << 9 |
                                   window.at(x - 3, y, z) << 11 | window.at(x, y - 3, z) << 12 |
                                   window.at(x - 2, y - 1, z) << 13 | window.at(x - 1, y - 2, z) << 14 |
                                   window.at(x + 1, y - 2, z) << 15 | window.at(x - 1, y, z - 2) << 16 |
                                   window.at(x, y - 1, z - 2) << 17;
          const std::array<unsigned, kCellModels> contexts = {
              before_x | before_y << 3 | under << 6 | diagonal << 7 | farther << 9 | near_beyond << 11 | set << 14 |
                  static_cast<unsigned>(z & 1) << 16 | is_last << 17,
              std::min(along_x, 3u) | std::min(along_y, 3u) << 2 | std::min(diagonals, 3u) << 4 | under << 6 |
                  near_beyond << 7 | set << 10 | is_last << 12 | static_cast<unsigned>(z) << 13,
              window.at(x - 3, y, z) | window.at(x, y - 3, z) << 1 | window.at(x - 2, y - 1, z) << 2 |
                  window.at(x - 1, y - 2, z) << 3 | window.at(x + 1, y - 2, z) << 4 | window.at(x - 2, y - 2, z) << 5 |
                  window.at(x + 2, y - 1, z) << 6 | farther << 7 | diagonal << 9 | middle_x << 11 | middle_y << 12 |
                  set << 13 | is_last << 15,
              under | window.at(x, y, z - 2) << 1 | window.at(x - 1, y, z + 1) << 2 | window.at(x, y - 1, z + 1) << 3 |
                  window.at(x - 1, y, z + 2) << 4 | window.at(x, y - 1, z + 2) << 5 | window.at(x - 1, y, z - 1) << 6 |
                  window.at(x, y - 1, z - 1) << 7 | window.at(x - 1, y, z - 2) << 8 | window.at(x, y - 1, z - 2) << 9 |
                  near_beyond << 10 | set << 13 | is_last << 15,
              static_cast<unsigned>(x) | static_cast<unsigned>(y) << 2 | static_cast<unsigned>(z) << 4 | set << 6 |
                  is_last << 8 | near_beyond << 9 | under << 12 | middle_x << 13 | middle_y << 14,
              (pattern * 2654435761u) >> 16};
          const unsigned mixer_set = set | is_last << 2 | (near_beyond & 4u) << 1;
          const unsigned map_context = set | is_last << 2 | under << 3 | middle_x << 4 | middle_y << 5 |
                                       static_cast<unsigned>(z) << 6;
          if (bit->code(coder, (actual >> cell_bit) & 1u, contexts, mixer_set, map_context)) {
            word |= std::uint64_t{1} << cell_bit;
            window.set(x, y, z);
            ++set_in[o];
          }
        }
    if constexpr (!kEncoding) words[b] = word;
  }
}

template <class Coder>
void code_mixed_level(Coder& coder, std::span<const Neighbours> near, std::span<std::uint64_t> words) {
  std::vector<std::uint8_t> octants(near.size(), 0);
  code_octants(coder, near, words, octants);
  code_cells(coder, near, words, octants);
}

}  // namespace

void encode_level_mixed(RangeEncoder& coder, std::span<const Neighbours> near, std::span<std::uint64_t> words) {
  code_mixed_level(coder, near, words);
}

void decode_level_mixed(RangeDecoder& coder, std::span<const Neighbours> near, std::span<std::uint64_t> words) {
  code_mixed_level(coder, near, words);
}

}  // namespace detail
VOLA_INLINE_NAMESPACE_END
}  // namespace vola
