// The voxels that can reflect sound: occupied voxels with at least one empty 6-neighbour
// (cells outside the grid count as empty). Found on the sparse tree, leaf block by leaf
// block: neighbours inside a block are bit shifts of its word, the others one
// Tree::contains each. Nothing dense is allocated.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "vola/tree.hpp"

namespace vola::audio {

// Bits of SurfaceVoxel::exposed: which faces have an empty neighbour.
enum Face : std::uint8_t { face_minus_x = 1, face_plus_x = 2, face_minus_y = 4, face_plus_y = 8, face_minus_z = 16, face_plus_z = 32 };

struct SurfaceVoxel {
  Voxel voxel;
  std::uint64_t rank = 0;      // index among all voxels in key order (attribute row)
  std::size_t leaf_block = 0;  // for Tree::voxel_payload_at_rank
  std::uint8_t exposed = 0;    // Face bits
};

// One leaf block of the tree with the rank of its first voxel.
struct LeafBlock {
  std::uint64_t word = 0;
  Voxel origin;
  std::uint64_t first_rank = 0;
  std::size_t index = 0;
};

std::vector<LeafBlock> leaf_blocks(const Tree& tree);

// A leaf block with at least one surface voxel, and per face (Face bit order: -x, +x, -y,
// +y, -z, +z) the block-word bits of its voxels whose neighbour there is empty. Found once
// per scene, so that each response walks words instead of asking the tree per voxel.
struct SurfaceBlock {
  std::uint64_t exposed[6] = {};
  Voxel origin;
  std::uint64_t word = 0;
  std::uint64_t first_rank = 0;
  std::size_t index = 0;
};

// The surface blocks of blocks, in key order (for_each_surface_voxel gathered per block).
std::vector<SurfaceBlock> surface_blocks(const Tree& tree, const std::vector<LeafBlock>& blocks);

// Calls f(const SurfaceVoxel&) for each surface voxel of blocks[begin, end), in key order.
template <class F>
void for_each_surface_voxel(const Tree& tree, const std::vector<LeafBlock>& blocks, std::size_t begin, std::size_t end, F&& f);

// Every surface voxel in key order (tests and small scenes).
std::vector<SurfaceVoxel> surface_voxels(const Tree& tree);

// ---- implementation ----

namespace detail {
// Bits of a 4x4x4 block word (bit = x + 4y + 16z) whose cell has the coordinate at 0 / 3.
inline constexpr std::uint64_t kX0 = 0x1111111111111111ull, kX3 = kX0 << 3;
inline constexpr std::uint64_t kY0 = 0x000F000F000F000Full, kY3 = kY0 << 12;
inline constexpr std::uint64_t kZ0 = 0xFFFFull, kZ3 = kZ0 << 48;

// For each of the 6 faces: the block's voxels whose neighbour there is known empty (inside
// the block), and those whose neighbour is in another block (to be asked of the tree).
struct FaceMasks {
  std::uint64_t empty[6];
  std::uint64_t outside[6];
};
inline FaceMasks face_masks(std::uint64_t w) noexcept {
  FaceMasks m;
  m.outside[0] = w & kX0;
  m.outside[1] = w & kX3;
  m.outside[2] = w & kY0;
  m.outside[3] = w & kY3;
  m.outside[4] = w & kZ0;
  m.outside[5] = w & kZ3;
  m.empty[0] = w & ~kX0 & ~(w << 1);
  m.empty[1] = w & ~kX3 & ~(w >> 1);
  m.empty[2] = w & ~kY0 & ~(w << 4);
  m.empty[3] = w & ~kY3 & ~(w >> 4);
  m.empty[4] = w & ~kZ0 & ~(w << 16);
  m.empty[5] = w & ~kZ3 & ~(w >> 16);
  return m;
}
}  // namespace detail

template <class F>
void for_each_surface_voxel(const Tree& tree, const std::vector<LeafBlock>& blocks, std::size_t begin, std::size_t end, F&& f) {
  static constexpr int kStep[6][3] = {{-1, 0, 0}, {1, 0, 0}, {0, -1, 0}, {0, 1, 0}, {0, 0, -1}, {0, 0, 1}};
  for (std::size_t i = begin; i < end; ++i) {
    const LeafBlock& block = blocks[i];
    const detail::FaceMasks m = detail::face_masks(block.word);
    std::uint64_t word = block.word;
    while (word) {
      const unsigned b = static_cast<unsigned>(std::countr_zero(word));
      const std::uint64_t bit = std::uint64_t{1} << b;
      word &= word - 1;
      const Voxel v{block.origin.x + (b & 3u), block.origin.y + ((b >> 2) & 3u), block.origin.z + (b >> 4)};
      std::uint8_t exposed = 0;
      for (int face = 0; face < 6; ++face) {
        if (m.empty[face] & bit) {
          exposed |= static_cast<std::uint8_t>(1u << face);
        } else if (m.outside[face] & bit) {
          // Unsigned wrap-around at 0 gives a cell outside the grid: contains() is false.
          const std::uint32_t nx = v.x + static_cast<std::uint32_t>(kStep[face][0]);
          const std::uint32_t ny = v.y + static_cast<std::uint32_t>(kStep[face][1]);
          const std::uint32_t nz = v.z + static_cast<std::uint32_t>(kStep[face][2]);
          if (!tree.contains(nx, ny, nz)) exposed |= static_cast<std::uint8_t>(1u << face);
        }
      }
      if (exposed)
        f(SurfaceVoxel{v, block.first_rank + static_cast<std::uint64_t>(std::popcount(block.word & (bit - 1))), block.index, exposed});
    }
  }
}

}  // namespace vola::audio
