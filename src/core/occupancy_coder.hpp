// Internal: context-modelled arithmetic coding of occupancy levels (compressed files,
// levels record flags 3; docs/FILE_FORMAT.md). Each level is coded with the levels above
// it known, in two passes over its blocks in file order:
//   A. per block, which of its eight 2x2x2 octants hold anything (8 bits), each bit in a
//      context of the neighbouring octants already coded and of which neighbouring blocks
//      exist (the level above says so);
//   B. per non-empty octant, its eight cells, each in a context of the three cells below
//      it along x, y and z (all coded by then, in this block or the previous ones) and of
//      the octants beyond it along x, y and z (all known after pass A).
// A block below the root is never empty and an octant of pass B never empty, so their
// last bit is implied when the others are 0. This is how octree geometry coders of point
// clouds work (occupancy of a node coded in the context of its neighbours' occupancy);
// a VOLA block is two octree levels.
//
// A block's neighbours come from the level above, as VOLA finds children: the block next
// to a child is a sibling (a bit of the same parent word) or a child of the parent's
// neighbour, and its index is that parent's first child plus a popcount.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "vola/version.hpp"

namespace vola {
VOLA_INLINE_NAMESPACE_BEGIN
namespace detail {

class OccupancyCoder {
 public:
  // How the bits are modelled: one context per bit (levels flags 3), or several contexts
  // mixed (flags 4, occupancy_mixed.hpp: smaller, slower).
  enum class Modelling { contexts, mixed };

  explicit OccupancyCoder(Modelling modelling = Modelling::contexts);  // before level 0: one block, at (0, 0, 0)

  // Blocks (words) of the next level.
  std::uint64_t blocks() const noexcept { return near_.size(); }
  // Codes the next level's words (words.size() == blocks()); `last` = no level follows.
  std::vector<std::uint8_t> encode(std::span<const std::uint64_t> words, bool last);
  // Decodes the next level into `words` (words.size() == blocks()); a stream that does
  // not decode to exactly its own bytes, or (unless `last`) to words whose set bits are
  // not the `next_words` blocks the file gives the level after it, is a FormatError naming
  // `name` and `offset` (before anything is allocated for that level).
  void decode(std::span<const std::uint8_t> stream, std::span<std::uint64_t> words, bool last,
              std::uint64_t next_words, const std::string& name, std::uint64_t offset);

  // The blocks next to a block of a level, by index in the level (kNoBlock: none): along
  // -x, +x, -y, +y, -z, +z, then below along x and y, x and z, y and z; the last entry is
  // always kNoBlock.
  static constexpr std::uint32_t kNoBlock = 0xFFFFFFFFu;
  struct Neighbours {
    std::array<std::uint32_t, 10> block;
  };

 private:
  void advance(std::span<const std::uint64_t> words, bool last);

  Modelling modelling_;
  std::vector<Neighbours> near_;  // of the next level's blocks, in file order
};

}  // namespace detail
VOLA_INLINE_NAMESPACE_END
}  // namespace vola
