#include "vola/audio/surface.hpp"

namespace vola::audio {

std::vector<LeafBlock> leaf_blocks(const Tree& tree) {
  std::vector<LeafBlock> blocks;
  blocks.reserve(static_cast<std::size_t>(tree.node_count(tree.depth() - 2 >= 0 ? tree.depth() - 2 : 0)));
  std::uint64_t rank = 0;
  tree.for_each_block(tree.depth() - 1, [&](std::size_t index, std::uint64_t word, std::uint32_t ox, std::uint32_t oy,
                                            std::uint32_t oz) {
    blocks.push_back(LeafBlock{word, Voxel{ox, oy, oz}, rank, index});
    rank += static_cast<std::uint64_t>(std::popcount(word));
  });
  return blocks;
}

std::vector<SurfaceBlock> surface_blocks(const Tree& tree, const std::vector<LeafBlock>& blocks) {
  std::vector<SurfaceBlock> out;
  for (std::size_t i = 0; i < blocks.size(); ++i) {
    const LeafBlock& block = blocks[i];
    SurfaceBlock s;
    s.origin = block.origin;
    s.word = block.word;
    s.first_rank = block.first_rank;
    s.index = block.index;
    bool any = false;
    for_each_surface_voxel(tree, blocks, i, i + 1, [&](const SurfaceVoxel& v) {
      const unsigned bit = (v.voxel.x - block.origin.x) + 4 * (v.voxel.y - block.origin.y) + 16 * (v.voxel.z - block.origin.z);
      for (int face = 0; face < 6; ++face)
        if (v.exposed & (1u << face)) s.exposed[face] |= std::uint64_t{1} << bit;
      any = true;
    });
    if (any) out.push_back(s);
  }
  return out;
}

std::vector<SurfaceVoxel> surface_voxels(const Tree& tree) {
  const std::vector<LeafBlock> blocks = leaf_blocks(tree);
  std::vector<SurfaceVoxel> out;
  for_each_surface_voxel(tree, blocks, 0, blocks.size(), [&](const SurfaceVoxel& s) { out.push_back(s); });
  return out;
}

}  // namespace vola::audio
