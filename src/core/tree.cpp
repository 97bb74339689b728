#include "vola/tree.hpp"

#include <cmath>
#include <limits>
#include <string>

#include "vola/error.hpp"

namespace vola {
VOLA_INLINE_NAMESPACE_BEGIN

namespace {
struct RankStorage {
  std::vector<std::uint64_t> super;
  std::vector<std::uint16_t> sub;
  std::vector<std::uint32_t> dense;
};
}  // namespace

RankDirectory::RankDirectory(std::span<const std::uint64_t> words, unsigned group_shift) : shift_(group_shift) {
  // Counts relative to the 512-word superblock fit in 16 bits (at most 511 * 64) for any
  // group size that divides 512.
  if (group_shift > 4)
    VOLA_THROW(InvalidArgument("rank directory: group shift " + std::to_string(group_shift) + " is above 4"));
  auto storage = std::make_shared<RankStorage>();
  const std::size_t n = words.size();
  if (shift_ == 0) {
    auto& dense = storage->dense;
    dense.resize(n + 1);
    std::uint64_t total = 0;
    for (std::size_t i = 0; i < n; ++i) {
      dense[i] = static_cast<std::uint32_t>(total);
      total += static_cast<std::uint64_t>(std::popcount(words[i]));
    }
    if (total <= std::numeric_limits<std::uint32_t>::max()) {
      dense[n] = static_cast<std::uint32_t>(total);
      total_ = total;
      dense_ = dense.data();
      bytes_ = dense.capacity() * sizeof(std::uint32_t);
      storage_ = std::move(storage);
      return;
    }
    std::vector<std::uint32_t>().swap(dense);  // too many bits for 32-bit counts
    shift_ = 3;
  }
  const std::size_t group_mask = (std::size_t{1} << shift_) - 1;
  auto& super = storage->super;
  auto& sub = storage->sub;
  super.resize(n / 512 + 1);
  sub.resize((n >> shift_) + 1);
  std::uint64_t total = 0;
  std::uint64_t super_base = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if ((i & 511) == 0) {
      super_base = total;
      super[i >> 9] = total;
    }
    if ((i & group_mask) == 0) sub[i >> shift_] = static_cast<std::uint16_t>(total - super_base);
    total += static_cast<std::uint64_t>(std::popcount(words[i]));
  }
  // Entries for index == n (a rank query one past the end).
  if ((n & 511) == 0) {
    super_base = total;
    super[n >> 9] = total;
  }
  if ((n & group_mask) == 0) sub[n >> shift_] = static_cast<std::uint16_t>(total - super_base);
  total_ = total;
  super_ = super.data();
  sub_ = sub.data();
  bytes_ = super.capacity() * sizeof(std::uint64_t) + sub.capacity() * sizeof(std::uint16_t);
  storage_ = std::move(storage);
}

namespace {
// Set bits in the first r words of a group of N (r < N), without a branch: the words
// past r are masked out. A loop of r steps costs a branch misprediction per level of a
// random lookup, and those flushes stop the CPU from overlapping the cache misses of
// consecutive lookups.
template <std::size_t N>
std::uint64_t masked_group_count(const std::uint64_t* group, std::size_t r) noexcept {
  std::uint64_t count = 0;
  for (std::size_t j = 0; j + 1 < N; ++j)
    count += static_cast<std::uint64_t>(std::popcount(group[j])) & (std::uint64_t{0} - (j < r));
  return count;
}
}  // namespace

std::uint64_t RankDirectory::before_grouped(std::span<const std::uint64_t> words, std::size_t index) const noexcept {
  std::uint64_t count = super_[index >> 9] + sub_[index >> shift_];
  const std::size_t group_size = std::size_t{1} << shift_;
  const std::size_t group = index & ~(group_size - 1);
  if (group + group_size <= words.size()) {  // a whole group: read all of it
    if (shift_ == 3) return count + masked_group_count<8>(words.data() + group, index - group);
    if (shift_ == 4) return count + masked_group_count<16>(words.data() + group, index - group);
  }
  for (std::size_t i = group; i < index; ++i) count += static_cast<std::uint64_t>(std::popcount(words[i]));
  return count;
}

Tree::Tree() {
  auto root = std::make_shared<std::vector<std::uint64_t>>(1, 0);
  all_words_ = *root;
  keeper_ = std::move(root);
  index({}, 0);
}

void Tree::set_frame(const Frame& frame) {
  if (!std::isfinite(frame.voxel_size))
    VOLA_THROW(OptionError("voxel_size", "must be finite, got " + std::to_string(frame.voxel_size)));
  for (int a = 0; a < 3; ++a)
    if (!std::isfinite(frame.origin[a])) VOLA_THROW(OptionError("origin", "must be finite"));
  frame_ = frame;
}

Tree Tree::from_levels(int depth, bool has_payload, std::vector<std::uint64_t> words,
                       const std::string& source, std::uint64_t file_offset) {
  auto owned = std::make_shared<std::vector<std::uint64_t>>(std::move(words));
  Tree tree = view_levels(depth, has_payload, *owned, owned, source, file_offset);
  tree.mapped_ = false;
  return tree;
}

Tree Tree::view_levels(int depth, bool has_payload, std::span<const std::uint64_t> words,
                       std::shared_ptr<const void> keeper, const std::string& source, std::uint64_t file_offset,
                       bool in_mapping) {
  if (depth < kMinDepth || depth > kMaxDepth)
    VOLA_THROW(InvalidArgument("depth " + std::to_string(depth) + " is outside 1..10"));
  Tree tree;
  tree.depth_ = depth;
  tree.has_payload_ = has_payload;
  tree.nbits_ = has_payload ? 1 : 0;
  tree.keeper_ = std::move(keeper);
  tree.all_words_ = words;
  tree.mapped_ = in_mapping;
  tree.index(source, file_offset);
  return tree;
}

// Splits the words into levels and builds the rank directory, checking that every
// level is as long as the level above promises.
void Tree::index(const std::string& source, std::uint64_t file_offset) {
  const std::size_t per_block = has_payload_ ? 2 : 1;
  std::size_t at = 0;
  std::uint64_t blocks = 1;
  for (int level = 0; level < depth_; ++level) {
    const std::uint64_t available = (all_words_.size() - at) / per_block;
    if (blocks > available) {
      VOLA_THROW(FormatError(source, file_offset + 8 * all_words_.size(),
                        "level " + std::to_string(level) + " needs " + std::to_string(blocks) +
                            " blocks of " + std::to_string(8 * per_block) + " bytes but only " +
                            std::to_string(available) + " remain (truncated file)"));
    }
    occupancy_[level] = all_words_.subspan(at, blocks);
    at += blocks;
    if (has_payload_) {
      payload_[level] = all_words_.subspan(at, blocks);
      at += blocks;
    } else {
      payload_[level] = {};
    }
    // One pass: the level's bits, and whether any word below the root is zero.
    std::uint64_t count = 0;
    bool zero = false;
    for (const std::uint64_t w : occupancy_[level]) {
      count += static_cast<std::uint64_t>(std::popcount(w));
      zero |= w == 0;
    }
    counts_[level] = count;
    if (level > 0 && zero) {
      for (std::size_t i = 0; i < occupancy_[level].size(); ++i) {
        if (occupancy_[level][i] == 0) {
          const std::uint64_t word_offset = (occupancy_[level].data() - all_words_.data()) + i;
          VOLA_THROW(FormatError(source, file_offset + 8 * word_offset,
                            "level " + std::to_string(level) + " block " + std::to_string(i) +
                                " is empty although its parent bit is set"));
        }
      }
    }
    blocks = counts_[level];
  }
  if (at != all_words_.size()) {
    VOLA_THROW(FormatError(source, file_offset + 8 * at,
                      std::to_string(8 * (all_words_.size() - at)) +
                          " bytes follow the last level that no level accounts for"));
  }
  // The directories, once every level's size is known (the group sizes depend on them).
  static constexpr std::uint64_t kZeroWord = 0;
  dense_levels_ = 0;
  for (int level = 0; level < depth_; ++level) {
    rank_[level] = RankDirectory(occupancy_[level], rank_group_shift(level));
    if (rank_[level].counts() && dense_levels_ == level) ++dense_levels_;
    steps_[level].words = occupancy_[level].empty() ? &kZeroWord : occupancy_[level].data();
    steps_[level].counts = rank_[level].counts();
  }
  for (int level = depth_; level < kMaxDepth; ++level) steps_[level] = Step{};
  // The jump table over the two top levels: 8 KiB, for trees whose leaf level is at least
  // 32768 words (256 KiB), so it adds at most 3%. Level 2 has at most 64^2 blocks, so a
  // block index fits in 15 bits.
  jump_.reset();
  if (depth_ >= 3 && occupancy_[depth_ - 1].size() >= (std::size_t{1} << 15)) {
    auto jump = std::make_shared<std::uint16_t[]>(4096);  // zeros: not occupied
    const std::uint64_t root = occupancy_[0][0];
    for (unsigned b0 = 0; b0 < 64; ++b0) {
      if (!((root >> b0) & 1u)) continue;
      const std::size_t c1 = static_cast<std::size_t>(std::popcount(root & ((std::uint64_t{1} << b0) - 1)));
      const std::uint64_t word = occupancy_[1][c1];
      const std::uint64_t base = rank_[1].before(occupancy_[1], c1);
      for (unsigned b1 = 0; b1 < 64; ++b1) {
        if (!((word >> b1) & 1u)) continue;
        const std::uint64_t c2 = base + static_cast<std::uint64_t>(std::popcount(word & ((std::uint64_t{1} << b1) - 1)));
        jump[b0 * 64 + b1] = static_cast<std::uint16_t>(0x8000u | c2);
      }
    }
    jump_ = std::move(jump);
  }
  fixed_walk_ = jump_ && dense_levels_ >= depth_ - 1 ? depth_ : 0;
}

// Every lookup ranks one block on each level above the leaf, so those directories decide
// lookup speed: the small upper levels get a count per word (one load, no popcount) as
// long as they hold, together, at most 1/8 as many words as the leaf level (their
// directory then costs at most 4 bytes per 8 leaf words, 6% of the leaf words). Bigger
// upper levels (a uniform scatter) keep a count every 8 words. The leaf level is ranked
// only by rank() and per-voxel payloads, so it gets the smallest directory (a count every
// 16 words).
unsigned Tree::rank_group_shift(int level) const noexcept {
  if (level == depth_ - 1) return 4;
  std::size_t upper = 0;
  for (int l = 0; l <= level; ++l) upper += occupancy_[l].size();
  return 8 * upper <= occupancy_[depth_ - 1].size() ? 0 : 3;
}

bool Tree::occupied_below(Key node_key, int level, int l, std::size_t block, std::uint64_t present) const noexcept {
  for (; l < level; ++l) {
    const std::uint64_t word = steps_[l].words[block];
    const unsigned bit = static_cast<unsigned>(node_key >> (6 * (level - l))) & 63u;
    present &= word >> bit;
    // (The empty levels of an empty tree: a zero word, and a directory that answers 0 for
    // block 0.)
    const std::size_t child = rank_[l].before(occupancy_[l], block) +
                              static_cast<std::size_t>(std::popcount(word & ((std::uint64_t{1} << bit) - 1)));
    block = child & (std::size_t{0} - static_cast<std::size_t>(present & 1u));
  }
  return (present & (steps_[level].words[block] >> (node_key & 63u)) & 1u) != 0;
}

std::optional<std::uint64_t> Tree::rank(const Voxel& v) const noexcept {
  if (!inside(v, depth_ - 1)) return std::nullopt;
  const auto at = locate(encode(v), depth_ - 1);
  if (!at) return std::nullopt;
  const auto& leaf = occupancy_[depth_ - 1];
  return rank_[depth_ - 1].before(leaf, at->block) +
         std::popcount(leaf[at->block] & ((std::uint64_t{1} << at->bit) - 1));
}

std::optional<std::uint64_t> Tree::block_payload(const Voxel& v) const noexcept {
  if (!has_payload_) return std::nullopt;
  if (!inside(v, depth_ - 1)) return std::nullopt;
  const auto at = locate(encode(v), depth_ - 1);
  if (!at) return std::nullopt;
  return payload_[depth_ - 1][at->block];
}

std::uint64_t Tree::voxel_payload_at_rank(std::uint64_t rank, std::size_t leaf_block) const noexcept {
  if (!voxel_payloads_.empty()) return voxel_payloads_[rank];
  if (has_payload_) return payload_[depth_ - 1][leaf_block];
  return 0;
}

std::optional<std::uint64_t> Tree::voxel_payload(const Voxel& v) const noexcept {
  if (!has_payload_ && voxel_payloads_.empty()) return std::nullopt;
  if (!inside(v, depth_ - 1)) return std::nullopt;
  const auto at = locate(encode(v), depth_ - 1);
  if (!at) return std::nullopt;
  std::uint64_t r = 0;
  if (!voxel_payloads_.empty()) {
    const auto& leaf = occupancy_[depth_ - 1];
    r = rank_[depth_ - 1].before(leaf, at->block) +
        std::popcount(leaf[at->block] & ((std::uint64_t{1} << at->bit) - 1));
  }
  return voxel_payload_at_rank(r, at->block);
}

void Tree::set_voxel_payloads(std::vector<std::uint64_t> payloads) {
  if (!payloads.empty() && payloads.size() != voxel_count())
    VOLA_THROW(InvalidArgument("voxel payloads: " + std::to_string(payloads.size()) + " values for " +
                          std::to_string(voxel_count()) + " voxels"));
  voxel_payloads_ = std::move(payloads);
  dense_coarse_payloads_.clear();
}

void Tree::set_payload_meaning(PayloadMeaning meaning) {
  if (meaning == PayloadMeaning::occupancy_state && !has_payload_)
    VOLA_THROW(InvalidArgument("an occupancy-state tree needs payload words (one per block)"));
  payload_meaning_ = meaning;
}

std::vector<Key> Tree::keys() const {
  std::vector<Key> out;
  out.reserve(voxel_count());
  for_each_voxel([&](const Voxel& v) { out.push_back(encode(v)); });
  return out;
}

Tree Tree::level_of_detail(int depth) const {
  if (depth < kMinDepth || depth > depth_)
    VOLA_THROW(InvalidArgument("level of detail: depth " + std::to_string(depth) + " is outside 1.." +
                          std::to_string(depth_)));
  if (depth == depth_) return *this;
  const auto& last = has_payload_ ? payload_[depth - 1] : occupancy_[depth - 1];
  const std::size_t end = static_cast<std::size_t>(last.data() + last.size() - all_words_.data());
  Tree coarse = view_levels(depth, has_payload_, all_words_.first(end), keeper_);
  coarse.mapped_ = mapped_;
  coarse.nbits_ = nbits_;
  coarse.georef_ = georef_;
  // A state map's coarser payload bits already say "any occupied voxel in this cell", so
  // the coarse tree is a state map of the coarser cells.
  coarse.payload_meaning_ = payload_meaning_;
  Frame f = frame();
  f.voxel_size *= static_cast<double>(std::uint64_t{1} << (2 * (depth_ - depth)));
  f.quantization = Quantization::grid;
  coarse.frame_ = f;
  return coarse;
}

std::size_t Tree::memory_bytes() const noexcept {
  std::size_t bytes = sizeof(Tree);
  if (!mapped_) bytes += all_words_.size() * sizeof(std::uint64_t);
  for (int level = 0; level < depth_; ++level) bytes += rank_[level].memory_bytes();
  if (jump_) bytes += 4096 * sizeof(std::uint16_t);
  for (const auto& column : attributes_.columns()) bytes += column.bytes().size();
  bytes += voxel_payloads_.capacity() * sizeof(std::uint64_t);
  return bytes;
}

Frame Tree::frame() const noexcept {
  if (frame_) return *frame_;
  return Quantizer::toolkit(georef_.bbox, depth_).frame();
}

Quantizer Tree::quantizer() const {
  if (frame_ && frame_->quantization == Quantization::grid)
    return Quantizer::grid(frame_->origin, frame_->voxel_size, depth_);
  Quantizer toolkit = Quantizer::toolkit(georef_.bbox, depth_);
  // A zero-extent bbox maps every point to voxel 0. A tree with other voxels was not
  // quantized by it (vola.build_from_voxels, vola_build_from_voxels): its grid is the
  // frame's, voxels one unit apart, as info and components already placed them (coords
  // put every voxel at the bbox's one point).
  const Frame fallback = toolkit.frame();
  if (!frame_ && fallback.voxel_size == 1.0 && voxel_count() > 0 && (voxel_count() > 1 || !contains(0, 0, 0))) {
    double extent = 0.0;
    for (int a = 0; a < 3; ++a) extent = std::max(extent, georef_.bbox.max[a] - georef_.bbox.min[a]);
    if (!(extent > 0.0)) return Quantizer::grid(fallback.origin, 1.0, depth_);
  }
  return toolkit;
}

VOLA_INLINE_NAMESPACE_END
}  // namespace vola
