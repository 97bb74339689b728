#include "dense.hpp"

#include <algorithm>

#include "emit.hpp"
#include "vola/builder.hpp"
#include "vola/error.hpp"

namespace vola {
VOLA_INLINE_NAMESPACE_BEGIN
namespace detail {

namespace {
std::uint64_t dense_index(const Voxel& cell, int level) noexcept {
  const std::uint64_t s = side_of(level + 1);
  return cell.x + s * (cell.y + s * std::uint64_t{cell.z});
}

// Offset, in words, of level L's occupancy in a dense body.
std::uint64_t dense_level_offset(int level, bool payload) noexcept {
  std::uint64_t at = 0;
  for (int l = 0; l < level; ++l) at += dense_level_words(l) * (payload ? 2 : 1);
  return at;
}

// Payload words of the levels above the leaf level (Tree::dense_coarse_payloads).
std::size_t coarse_payload_words(int depth) noexcept {
  std::size_t words = 0;
  for (int l = 0; l + 1 < depth; ++l) words += dense_level_words(l);
  return words;
}
}  // namespace

std::uint64_t dense_body_words(int depth, bool payload) noexcept { return dense_level_offset(depth, payload); }

std::vector<std::uint64_t> encode_dense(const Tree& tree) {
  const int depth = tree.depth();
  const bool payload = tree.has_payload() || !tree.voxel_payloads().empty();
  std::vector<std::uint64_t> body(dense_body_words(depth, payload), 0);
  for (int level = 0; level < depth; ++level) {
    std::uint64_t* occupancy = body.data() + dense_level_offset(level, payload);
    tree.for_each_node(level, [&](const Voxel& cell) {
      const std::uint64_t i = dense_index(cell, level);
      occupancy[i >> 6] |= std::uint64_t{1} << (i & 63);
    });
  }
  if (!payload) return body;
  // A tree read from a dense file gives its coarse levels' words back as read.
  const std::span<const std::uint64_t> kept = tree.dense_coarse_payloads();
  const int computed_from = kept.size() == coarse_payload_words(depth) ? depth - 1 : 0;
  std::size_t at = 0;
  for (int level = 0; level < computed_from; ++level) {
    const std::uint64_t n = dense_level_words(level);
    std::copy_n(kept.begin() + static_cast<std::ptrdiff_t>(at), n,
                body.begin() + static_cast<std::ptrdiff_t>(dense_level_offset(level, true) + n));
    at += n;
  }
  // Payload of a dense word: that of the lexicographically greatest (x, y, z) voxel
  // with a non-zero payload among the voxels whose level-L cell lies in the word.
  // Voxels come in key order, so keep the best order seen per word.
  std::vector<std::vector<std::uint64_t>> best(depth);
  for (int level = 0; level < depth; ++level) best[level].assign(dense_level_words(level), 0);
  std::uint64_t rank = 0;
  tree.for_each_block(depth - 1, [&](std::size_t block, std::uint64_t word, std::uint32_t ox, std::uint32_t oy,
                                     std::uint32_t oz) {
    while (word) {
      const unsigned b = static_cast<unsigned>(std::countr_zero(word));
      word &= word - 1;
      const Voxel v{ox + (b & 3u), oy + ((b >> 2) & 3u), oz + (b >> 4)};
      const std::uint64_t p = tree.voxel_payload_at_rank(rank++, block);
      if (p == 0) continue;
      const std::uint64_t order = ((std::uint64_t{v.x} << 40) | (std::uint64_t{v.y} << 20) | v.z) + 1;
      for (int level = computed_from; level < depth; ++level) {
        const int shift = 2 * (depth - 1 - level);
        const std::uint64_t w = dense_index(Voxel{v.x >> shift, v.y >> shift, v.z >> shift}, level) >> 6;
        if (order > best[level][w]) {
          best[level][w] = order;
          body[dense_level_offset(level, true) + dense_level_words(level) + w] = p;
        }
      }
    }
  });
  return body;
}

Tree decode_dense(std::span<const std::uint64_t> words, int depth, bool payload, const std::string& name,
                  std::uint64_t base_offset) {
  const std::uint64_t leaf_offset = dense_level_offset(depth - 1, payload);
  const std::uint64_t leaf_words = dense_level_words(depth - 1);
  const std::uint64_t s = side_of(depth);
  std::vector<Key> keys;
  std::vector<std::uint32_t> order;
  std::vector<std::uint64_t> word_payload;
  for (std::uint64_t w = 0; w < leaf_words; ++w) {
    std::uint64_t bits = words[leaf_offset + w];
    while (bits) {
      const unsigned b = static_cast<unsigned>(std::countr_zero(bits));
      bits &= bits - 1;
      const std::uint64_t i = (w << 6) | b;
      keys.push_back(encode(static_cast<std::uint32_t>(i % s), static_cast<std::uint32_t>((i / s) % s),
                            static_cast<std::uint32_t>(i / (s * s))));
      if (payload) {
        order.push_back(static_cast<std::uint32_t>(order.size()));
        word_payload.push_back(words[leaf_offset + leaf_words + w]);
      }
    }
  }
  radix_sort(keys, payload ? &order : nullptr, 6 * depth);
  std::vector<std::uint64_t> voxel_payloads;
  if (payload) {
    voxel_payloads.resize(keys.size());
    for (std::size_t i = 0; i < keys.size(); ++i) voxel_payloads[i] = word_payload[order[i]];
  }
  Tree tree = emit_levels(keys, depth, voxel_payloads, payload);
  if (payload) {
    tree.set_voxel_payloads(std::move(voxel_payloads));
    std::vector<std::uint64_t> coarse;
    coarse.reserve(coarse_payload_words(depth));
    for (int level = 0; level + 1 < depth; ++level) {
      const std::uint64_t* at = words.data() + dense_level_offset(level, true) + dense_level_words(level);
      coarse.insert(coarse.end(), at, at + dense_level_words(level));
    }
    tree.set_dense_coarse_payloads(std::move(coarse));
  }

  for (int level = 0; level + 1 < depth; ++level) {
    const std::uint64_t* occupancy = words.data() + dense_level_offset(level, payload);
    const std::uint64_t offset = base_offset + 8 * dense_level_offset(level, payload);
    std::uint64_t set = 0;
    for (std::uint64_t w = 0; w < dense_level_words(level); ++w) set += std::popcount(occupancy[w]);
    bool agrees = set == tree.node_count(level);
    if (agrees) {
      tree.for_each_node(level, [&](const Voxel& cell) {
        const std::uint64_t i = dense_index(cell, level);
        agrees = agrees && ((occupancy[i >> 6] >> (i & 63)) & 1u);
      });
    }
    if (!agrees)
      VOLA_THROW(FormatError(name, offset,
                        "dense level " + std::to_string(level) + " has " + std::to_string(set) +
                            " occupied cells that disagree with the " + std::to_string(tree.node_count(level)) +
                            " cells the leaf level implies"));
  }
  return tree;
}

}  // namespace detail
VOLA_INLINE_NAMESPACE_END
}  // namespace vola
