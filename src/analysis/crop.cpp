// Leaf blocks wholly inside the box are copied word by word, blocks that straddle it
// are masked bit by bit, the rest skipped.
#include <bit>
#include <cstdint>
#include <string>
#include <vector>

#include "same_frame.hpp"
#include "vola/analysis/crop.hpp"
#include "vola/builder.hpp"
#include "vola/error.hpp"

namespace vola::analysis {

Tree crop(const Tree& tree, const Voxel& min, const Voxel& max) {
  // A box whose max lies below its min on an axis (the corners swapped) holds nothing:
  // refused rather than written as an empty file.
  const std::uint32_t lo[3] = {min.x, min.y, min.z}, hi[3] = {max.x, max.y, max.z};
  for (int a = 0; a < 3; ++a)
    if (hi[a] < lo[a])
      throw InvalidArgument("crop box: max " + std::string(1, "xyz"[a]) + " = " + std::to_string(hi[a]) +
                            " is below min " + std::string(1, "xyz"[a]) + " = " + std::to_string(lo[a]) +
                            " (min is the first voxel, max the last, both inclusive)");
  std::vector<Key> keys;
  if (!tree.empty())
    tree.for_each_block(tree.depth() - 1, [&](std::size_t, std::uint64_t word, std::uint32_t ox, std::uint32_t oy,
                                              std::uint32_t oz) {
      if (ox + 3 < min.x || oy + 3 < min.y || oz + 3 < min.z || ox > max.x || oy > max.y || oz > max.z) return;
      const Key block = encode(ox / 4, oy / 4, oz / 4) << 6;
      while (word) {
        const unsigned b = static_cast<unsigned>(std::countr_zero(word));
        word &= word - 1;
        const std::uint32_t x = ox + (b & 3u), y = oy + ((b >> 2) & 3u), z = oz + (b >> 4);
        if (x >= min.x && y >= min.y && z >= min.z && x <= max.x && y <= max.y && z <= max.z) keys.push_back(block | b);
      }
    });
  return detail::with_frame_of(build_from_sorted_keys(keys, tree.depth()), tree);
}

}  // namespace vola::analysis
