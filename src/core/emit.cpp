#include "emit.hpp"

#include <bit>

namespace vola {
VOLA_INLINE_NAMESPACE_BEGIN
namespace detail {

namespace {
// Order of the reference's insertion: x major, then y, then z.
std::uint64_t lexicographic(const Voxel& v) noexcept {
  return (std::uint64_t{v.x} << 40) | (std::uint64_t{v.y} << 20) | v.z;
}

}  // namespace

// One pass over sorted unique keys emits every level. For each key, the highest digit
// in which it differs from the previous key says which levels start a new block.
// Block payloads follow the reference: the payload of the lexicographically greatest
// (x, y, z) voxel in the block whose payload is not zero.
Tree emit_levels(std::span<const Key> keys, int depth, std::span<const std::uint64_t> voxel_payloads,
                 bool with_payload) {
  std::vector<std::vector<std::uint64_t>> occupancy(depth), payload(depth), best(depth);
  occupancy[0].push_back(0);
  if (with_payload) {
    payload[0].push_back(0);
    best[0].push_back(0);
  }
  if (!keys.empty()) occupancy[depth - 1].reserve(keys.size() / 2 + 1);
  Key previous = 0;
  for (std::size_t i = 0; i < keys.size(); ++i) {
    const Key key = keys[i];
    int first_changed = 0;  // the shallowest level whose digit changes
    if (i > 0) {
      const Key diff = key ^ previous;
      const int high_bit = 63 - std::countl_zero(diff);
      first_changed = depth - 1 - high_bit / 6;
    }
    for (int level = first_changed + 1; level < depth; ++level) {
      occupancy[level].push_back(0);
      if (with_payload) {
        payload[level].push_back(0);
        best[level].push_back(0);
      }
    }
    for (int level = first_changed; level < depth; ++level)
      occupancy[level].back() |= std::uint64_t{1} << digit(key, level, depth);
    if (with_payload) {
      const std::uint64_t p = voxel_payloads[i];
      if (p != 0) {
        const std::uint64_t order = lexicographic(decode(key)) + 1;  // 0 = no voxel yet
        for (int level = 0; level < depth; ++level) {
          if (order > best[level].back()) {
            best[level].back() = order;
            payload[level].back() = p;
          }
        }
      }
    }
    previous = key;
  }
  std::size_t total = 0;
  for (int level = 0; level < depth; ++level) total += occupancy[level].size() * (with_payload ? 2 : 1);
  std::vector<std::uint64_t> words;
  words.reserve(total);
  for (int level = 0; level < depth; ++level) {
    words.insert(words.end(), occupancy[level].begin(), occupancy[level].end());
    std::vector<std::uint64_t>().swap(occupancy[level]);
    if (with_payload) words.insert(words.end(), payload[level].begin(), payload[level].end());
  }
  return Tree::from_levels(depth, with_payload, std::move(words));
}

Tree emit_block_levels(std::span<const Key> blocks, std::span<const std::uint64_t> bits, int depth) {
  if (depth == 1) return Tree::from_levels(1, false, {blocks.empty() ? std::uint64_t{0} : bits[0]});
  // Levels 0 .. depth-2 are those of a depth-1 tree whose voxels are the blocks.
  const int upper = depth - 1;
  std::vector<std::vector<std::uint64_t>> occupancy(upper);
  occupancy[0].push_back(0);
  if (!blocks.empty()) occupancy[upper - 1].reserve(blocks.size() / 4 + 1);
  Key previous = 0;
  for (std::size_t i = 0; i < blocks.size(); ++i) {
    const Key key = blocks[i];
    int first_changed = 0;
    if (i > 0) first_changed = upper - 1 - (63 - std::countl_zero(key ^ previous)) / 6;
    for (int level = first_changed + 1; level < upper; ++level) occupancy[level].push_back(0);
    for (int level = first_changed; level < upper; ++level)
      occupancy[level].back() |= std::uint64_t{1} << digit(key, level, upper);
    previous = key;
  }
  std::size_t total = bits.size();
  for (int level = 0; level < upper; ++level) total += occupancy[level].size();
  std::vector<std::uint64_t> words;
  words.reserve(total);
  for (int level = 0; level < upper; ++level) {
    words.insert(words.end(), occupancy[level].begin(), occupancy[level].end());
    std::vector<std::uint64_t>().swap(occupancy[level]);
  }
  words.insert(words.end(), bits.begin(), bits.end());
  return Tree::from_levels(depth, false, std::move(words));
}

}  // namespace detail
VOLA_INLINE_NAMESPACE_END
}  // namespace vola
