// The frozen VOLA tree: levels of 64-bit occupancy words laid out exactly as in a
// sparse .vol file, plus an in-memory rank directory so that finding a child, a
// voxel's rank or a coarser node takes `depth` steps and no allocation.
//
// Build one with vola::build (builder.hpp) or open one with vola::read /
// vola::open_mapped (file.hpp). A tree is immutable; edit by building anew or by the
// set operations (setops.hpp), which merge sorted key lists.
#pragma once

#include <array>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include "vola/attributes.hpp"
#include "vola/frame.hpp"
#include "vola/key.hpp"
#include "vola/version.hpp"

namespace vola {
VOLA_INLINE_NAMESPACE_BEGIN

// Popcount rank over one level's words: a 64-bit count every 512 words and a 16-bit
// count (relative to it) every 2^group_shift words; the words between a count and the
// index asked for are counted with popcount.
//   group_shift 3 (the default): 2.1 bits of directory per 64-bit word, up to 7 popcounts.
//   group_shift 4: 1.1 bits per word, up to 15 popcounts; the tree's leaf level, which
//                  lookups never rank (only rank() and per-voxel payloads do).
//   group_shift 0: instead, a 32-bit count for every word (32 bits per word), one load
//                  and no popcount; the tree's small upper levels, which every lookup
//                  walks. Levels with 2^32 set bits or more fall back to 3.
// Copies share the (immutable) counts.
class RankDirectory {
 public:
  RankDirectory() = default;
  explicit RankDirectory(std::span<const std::uint64_t> words) : RankDirectory(words, 3) {}
  // group_shift: 0, 1, 2, 3 or 4.
  RankDirectory(std::span<const std::uint64_t> words, unsigned group_shift);

  // Number of set bits in words[0 .. index).
  std::uint64_t before(std::span<const std::uint64_t> words, std::size_t index) const noexcept {
    if (dense_) return dense_[index];
    return before_grouped(words, index);
  }
  // The count before every word (group_shift 0), or nullptr.
  const std::uint32_t* counts() const noexcept { return dense_; }
  std::uint64_t total() const noexcept { return total_; }
  unsigned group_shift() const noexcept { return shift_; }
  std::size_t memory_bytes() const noexcept { return bytes_; }

 private:
  // Out of line, so that the one-load path above stays small where it is inlined.
  std::uint64_t before_grouped(std::span<const std::uint64_t> words, std::size_t index) const noexcept;

  const std::uint64_t* super_ = nullptr;
  const std::uint16_t* sub_ = nullptr;
  const std::uint32_t* dense_ = nullptr;  // group_shift 0: the count before every word
  std::shared_ptr<const void> storage_;   // owns the arrays above
  std::size_t bytes_ = 0;
  std::uint64_t total_ = 0;
  unsigned shift_ = 3;
};

// What a tree's payload words mean.
//  reference:       the reference toolkit's: one word per block, the row of the block's
//                   lexicographically greatest voxel (FORMAT.md section 8), or none.
//  occupancy_state: a state map (vola/map/state_map.hpp): the tree holds every KNOWN voxel
//                   and bit b of a leaf block's payload word is 1 iff voxel b is occupied,
//                   0 iff free; at coarser levels bit b is 1 iff cell b holds any occupied
//                   voxel. Unknown space is outside the tree. Written in the extension
//                   (record 5, docs/FILE_FORMAT.md); a reference reader sees the known voxels.
enum class PayloadMeaning : std::uint8_t { reference = 0, occupancy_state = 1 };

class Tree {
 public:
  // An empty tree of depth 1 (one zero root word).
  Tree();

  // Takes the level words in sparse file order (for each level: occupancy words,
  // then payload words when has_payload) and checks them: level 0 is one word,
  // each level has as many words as the level above has set bits, no word below
  // the root is zero. Throws FormatError naming `source` otherwise.
  // `file_offset` = where the words start in `source`, for the error's byte offset.
  static Tree from_levels(int depth, bool has_payload, std::vector<std::uint64_t> words,
                          const std::string& source = {}, std::uint64_t file_offset = 0);
  // The same over bytes kept alive by `keeper` (a memory map): nothing is copied.
  // `in_mapping`: whether the bytes are a file's mapping (is_mapped), not a copy of it.
  static Tree view_levels(int depth, bool has_payload, std::span<const std::uint64_t> words,
                          std::shared_ptr<const void> keeper, const std::string& source = {},
                          std::uint64_t file_offset = 0, bool in_mapping = true);

  int depth() const noexcept { return depth_; }
  std::uint32_t side() const noexcept { return side_of(depth_); }
  std::uint64_t voxel_count() const noexcept { return counts_[depth_ - 1]; }
  bool empty() const noexcept { return voxel_count() == 0; }
  // Occupied cells at `level` (level depth-1 = voxels).
  std::uint64_t node_count(int level) const noexcept { return counts_[level]; }
  std::span<const std::uint64_t> occupancy(int level) const noexcept { return occupancy_[level]; }
  // Block payload words of `level` (empty when the tree has none).
  std::span<const std::uint64_t> payload(int level) const noexcept { return payload_[level]; }
  bool has_payload() const noexcept { return has_payload_; }
  // All level words in sparse file order.
  std::span<const std::uint64_t> words() const noexcept { return all_words_; }

  bool contains(std::uint32_t x, std::uint32_t y, std::uint32_t z) const noexcept {
    // `&`, not `&&`: no branch. The walks read only the key's low 6 * depth bits, so they
    // are safe for any coordinates.
    const bool in = inside(Voxel{x, y, z}, depth_ - 1);
    const Key key = encode(x, y, z);
    switch (fixed_walk_) {  // the same every call: predicted
      case 3: return in & occupied_fixed<3>(key);
      case 4: return in & occupied_fixed<4>(key);
      case 5: return in & occupied_fixed<5>(key);
      case 6: return in & occupied_fixed<6>(key);
      case 7: return in & occupied_fixed<7>(key);
      case 8: return in & occupied_fixed<8>(key);
      case 9: return in & occupied_fixed<9>(key);
      case 10: return in & occupied_fixed<10>(key);
      default: return in & occupied(key, depth_ - 1);
    }
  }
  bool contains(const Voxel& v) const noexcept { return contains(v.x, v.y, v.z); }
  // Is the level-`level` cell (coordinates on the 4^(level+1) grid) occupied?
  bool contains_node(int level, const Voxel& cell) const noexcept {
    return inside(cell, level) & occupied(encode(cell.x, cell.y, cell.z), level);
  }
  // The voxel's index among all voxels in key order, if occupied: the row of its
  // attribute values.
  std::optional<std::uint64_t> rank(const Voxel& v) const noexcept;
  // The payload word of the voxel's leaf block (reference semantics), if occupied.
  std::optional<std::uint64_t> block_payload(const Voxel& v) const noexcept;
  // The voxel's own payload: the per-voxel payloads of a tree built from points or
  // read from a dense file, else its leaf block's payload word.
  std::optional<std::uint64_t> voxel_payload(const Voxel& v) const noexcept;
  std::uint64_t voxel_payload_at_rank(std::uint64_t rank, std::size_t leaf_block) const noexcept;

  // Visits every voxel in key order: f(const Voxel&).
  template <class F>
  void for_each_voxel(F&& f) const {
    for_each_node(depth_ - 1, std::forward<F>(f));
  }
  // Visits every occupied cell of `level` in key order: f(const Voxel& cell).
  template <class F>
  void for_each_node(int level, F&& f) const {
    for_each_block(level, [&](std::size_t, std::uint64_t word, std::uint32_t ox, std::uint32_t oy,
                              std::uint32_t oz) {
      while (word) {
        const unsigned b = static_cast<unsigned>(std::countr_zero(word));
        word &= word - 1;
        f(Voxel{ox + (b & 3u), oy + ((b >> 2) & 3u), oz + (b >> 4)});
      }
    });
  }
  // Visits every block (word) of `level` in order:
  // f(block index, occupancy word, origin x, origin y, origin z), where the origin is
  // the block's first cell on the level's 4^(level+1) grid. No rank lookups: blocks
  // of a level are visited in storage order.
  template <class F>
  void for_each_block(int level, F&& f) const {
    if (empty()) return;
    std::array<std::size_t, kMaxDepth> next{};  // next unvisited block per level
    visit_block(0, level, next, 0, 0, 0, f);
  }
  // All voxel keys, sorted.
  std::vector<Key> keys() const;

  // The first `depth` levels as a tree of that depth: each voxel is one level-(depth-1)
  // cell of this tree. Shares this tree's words; the frame's voxel size grows by 4 per
  // level dropped.
  Tree level_of_detail(int depth) const;

  // Bytes held in memory: owned words, rank directory, attributes (a memory-mapped
  // tree's words are not counted: they live in the page cache).
  std::size_t memory_bytes() const noexcept;
  bool is_mapped() const noexcept { return mapped_; }

  // Metadata carried in the header and our extension.
  Georef& georef() noexcept { return georef_; }
  const Georef& georef() const noexcept { return georef_; }
  // The header's nbits value, kept as read (0 without payload).
  std::uint32_t nbits() const noexcept { return nbits_; }
  void set_nbits(std::uint32_t nbits) noexcept { nbits_ = has_payload_ ? (nbits ? nbits : 1) : 0; }
  // nullopt when the file had no extension (a reference file): its grid is then the
  // toolkit's, from the header bbox.
  const std::optional<Frame>& stored_frame() const noexcept { return frame_; }
  // Throws InvalidArgument for a frame whose origin or voxel size is not finite (a file
  // written with it is one the reader refuses).
  void set_frame(const Frame& frame);
  // The grid in world coordinates, whichever way it is known.
  Frame frame() const noexcept;
  Quantizer quantizer() const;
  Attributes& attributes() noexcept { return attributes_; }
  const Attributes& attributes() const noexcept { return attributes_; }
  PayloadMeaning payload_meaning() const noexcept { return payload_meaning_; }
  // occupancy_state needs payload words (InvalidArgument otherwise).
  void set_payload_meaning(PayloadMeaning meaning);
  std::span<const std::uint64_t> voxel_payloads() const noexcept { return voxel_payloads_; }
  // One payload per voxel in rank order (size voxel_count()). Drops the dense file's
  // coarse payload words (below): they described the payloads before.
  void set_voxel_payloads(std::vector<std::uint64_t> payloads);
  // A tree read from a dense file keeps the payload words of its coarse levels (levels
  // 0 .. depth-2, each level's words in the dense layout, one after another): each is the
  // payload of the greatest voxel with a non-zero payload in its cells, which per-voxel
  // payloads cannot give back (a voxel read from a dense file has its 64-cell run's
  // word, not its own point's payload), so that writing the tree dense again keeps them.
  std::span<const std::uint64_t> dense_coarse_payloads() const noexcept { return dense_coarse_payloads_; }
  void set_dense_coarse_payloads(std::vector<std::uint64_t> words) { dense_coarse_payloads_ = std::move(words); }

 private:
  struct Location {
    std::size_t block;  // block index within the level
    unsigned bit;       // bit within the block
  };
  // Is the cell on the level's 4^(level+1) grid? Cells past it would alias onto cells
  // inside it, since a key keeps only the low 2 bits per level of each coordinate.
  static bool inside(const Voxel& cell, int level) noexcept {
    return ((cell.x | cell.y | cell.z) >> (2 * (level + 1))) == 0;
  }
  // Is the cell of `node_key` (a key of a depth-(level+1) tree) occupied? The walk of
  // locate() without a branch on the way: a walk that has left the tree goes on at block
  // 0 of each level (always there, and in cache) and the answer is the AND of the bits
  // met. Random lookups then cost no branch mispredictions (half of them miss, at
  // unpredictable levels), so the CPU overlaps the cache misses of several lookups;
  // that is worth more than stopping early. The first two levels are one table lookup
  // when the tree has the table, the next ones one load each while their directories
  // have a count per word (see index()); the loop has no call in it, so the compiler
  // unrolls it. Any other level is walked out of line.
  bool occupied(Key node_key, int level) const noexcept {
    std::size_t block = 0;
    std::uint64_t present = 1;
    int l = 0;
    if (jump_ && level >= 2) {
      const std::uint16_t entry = jump_[static_cast<std::size_t>(node_key >> (6 * (level - 1))) & 4095u];
      present = entry >> 15;
      block = entry & 0x7fffu;
      l = 2;
    }
    const int dense_end = level < dense_levels_ ? level : dense_levels_;
    for (; l < dense_end; ++l) {
      const std::uint64_t word = steps_[l].words[block];
      const unsigned bit = static_cast<unsigned>(node_key >> (6 * (level - l))) & 63u;
      present &= word >> bit;
      const std::size_t child = steps_[l].counts[block] +
                                static_cast<std::size_t>(std::popcount(word & ((std::uint64_t{1} << bit) - 1)));
      block = child & (std::size_t{0} - static_cast<std::size_t>(present & 1u));
    }
    if (l < level) return occupied_below(node_key, level, l, block, present);
    return (present & (steps_[level].words[block] >> (node_key & 63u)) & 1u) != 0;
  }
  // occupied(key, Depth - 1) for trees with the jump table and a count per word on every
  // level above the leaf (fixed_walk_ == Depth): with the depth known at compile time the
  // walk unrolls into straight-line code with constant shifts, a quarter fewer
  // instructions than the general walk, which is what random lookups are bound by once
  // their cache misses overlap.
  template <int Depth>
  bool occupied_fixed(Key key) const noexcept {
    const std::uint16_t entry = jump_[static_cast<std::size_t>(key >> (6 * (Depth - 2))) & 4095u];
    std::uint64_t present = entry >> 15;
    std::size_t block = entry & 0x7fffu;
    for (int l = 2; l < Depth - 1; ++l) {
      const std::uint64_t word = steps_[l].words[block];
      const unsigned bit = static_cast<unsigned>(key >> (6 * (Depth - 1 - l))) & 63u;
      present &= word >> bit;
      const std::size_t child = steps_[l].counts[block] +
                                static_cast<std::size_t>(std::popcount(word & ((std::uint64_t{1} << bit) - 1)));
      block = child & (std::size_t{0} - static_cast<std::size_t>(present & 1u));
    }
    return (present & (steps_[Depth - 1].words[block] >> (key & 63u)) & 1u) != 0;
  }
  // occupied() from level `l` on, through the grouped directories.
  bool occupied_below(Key node_key, int level, int l, std::size_t block, std::uint64_t present) const noexcept;

  // Walks from the root to `level` along `key` (a key of a depth-(level+1) tree).
  std::optional<Location> locate(Key node_key, int level) const noexcept {
    std::size_t block = 0;
    for (int l = 0;; ++l) {
      const std::uint64_t word = occupancy_[l][block];
      const unsigned bit = static_cast<unsigned>(node_key >> (6 * (level - l))) & 63u;
      if (!((word >> bit) & 1u)) return std::nullopt;
      if (l == level) return Location{block, bit};
      block = rank_[l].before(occupancy_[l], block) +
              std::popcount(word & ((std::uint64_t{1} << bit) - 1));
    }
  }

  template <class F>
  void visit_block(int level, int last_level, std::array<std::size_t, kMaxDepth>& next,
                   std::uint32_t ox, std::uint32_t oy, std::uint32_t oz, F& f) const {
    const std::size_t block = next[level]++;
    std::uint64_t word = occupancy_[level][block];
    if (level == last_level) {
      f(block, word, ox, oy, oz);
      return;
    }
    if (level + 1 == last_level) {
      // The children are consecutive blocks of the last level: visit them in this loop
      // rather than one recursive call each (most blocks of a tree are last-level blocks).
      const std::uint64_t* child_words = occupancy_[last_level].data();
      std::size_t child = next[last_level];
      while (word) {
        const unsigned b = static_cast<unsigned>(std::countr_zero(word));
        word &= word - 1;
        f(child, child_words[child], (ox + (b & 3u)) * 4, (oy + ((b >> 2) & 3u)) * 4, (oz + (b >> 4)) * 4);
        ++child;
      }
      next[last_level] = child;
      return;
    }
    while (word) {
      const unsigned b = static_cast<unsigned>(std::countr_zero(word));
      word &= word - 1;
      visit_block(level + 1, last_level, next, (ox + (b & 3u)) * 4, (oy + ((b >> 2) & 3u)) * 4,
                  (oz + (b >> 4)) * 4, f);
    }
  }

  void index(const std::string& source, std::uint64_t file_offset);
  // The rank directory's group size for `level` once the level sizes are known.
  unsigned rank_group_shift(int level) const noexcept;

  int depth_ = 1;
  bool has_payload_ = false;
  bool mapped_ = false;
  std::uint32_t nbits_ = 0;
  std::shared_ptr<const void> keeper_;  // owns or maps the words
  std::span<const std::uint64_t> all_words_;
  std::array<std::span<const std::uint64_t>, kMaxDepth> occupancy_{};
  std::array<std::span<const std::uint64_t>, kMaxDepth> payload_{};
  std::array<RankDirectory, kMaxDepth> rank_{};
  // Big trees: the level-2 block of every 2-digit key prefix (4096 entries, bit 15 =
  // occupied), so that lookups skip the two top levels. Empty otherwise.
  std::shared_ptr<const std::uint16_t[]> jump_;  // shared by copies
  // What occupied() reads per level: the occupancy words (a zero word for the empty
  // levels of an empty tree, so that block 0 always exists) and, for levels
  // 0 .. dense_levels_-1, the count before each word. Both outlive copies of the tree:
  // the words belong to keeper_, the counts are shared by the rank directories.
  struct Step {
    const std::uint64_t* words = nullptr;
    const std::uint32_t* counts = nullptr;
  };
  std::array<Step, kMaxDepth> steps_{};
  int dense_levels_ = 0;
  int fixed_walk_ = 0;  // the depth when occupied_fixed<depth> applies, else 0
  std::array<std::uint64_t, kMaxDepth> counts_{};
  Georef georef_;
  std::optional<Frame> frame_;
  Attributes attributes_;
  std::vector<std::uint64_t> voxel_payloads_;
  std::vector<std::uint64_t> dense_coarse_payloads_;
  PayloadMeaning payload_meaning_ = PayloadMeaning::reference;
};

VOLA_INLINE_NAMESPACE_END
}  // namespace vola
