// Internal: the reference's dense layout (mode 1). Level L is a flat bitmap of the
// 4^(L+1)-side grid in x-fastest order; a word is a run of 64 cells along x.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "vola/tree.hpp"

namespace vola {
VOLA_INLINE_NAMESPACE_BEGIN
namespace detail {

// Words of a dense level-L bitmap: 64^L.
constexpr std::uint64_t dense_level_words(int level) noexcept { return std::uint64_t{1} << (6 * level); }
// Words of a whole dense file body (with payload words when `payload`).
std::uint64_t dense_body_words(int depth, bool payload) noexcept;

// The dense body of a tree. Payload words follow the reference's rule over the
// tree's per-voxel payloads (or its leaf block payloads when it has none).
std::vector<std::uint64_t> encode_dense(const Tree& tree);
// Dense body -> tree; per-voxel payloads are those of each voxel's leaf dense word.
// Checks that every coarser level agrees with the leaf level.
Tree decode_dense(std::span<const std::uint64_t> words, int depth, bool payload, const std::string& name,
                  std::uint64_t base_offset);

}  // namespace detail
VOLA_INLINE_NAMESPACE_END
}  // namespace vola
