#include "vola/tree.hpp"

#include <string>

#include "vola/error.hpp"

namespace vola {
VOLA_INLINE_NAMESPACE_BEGIN

RankDirectory::RankDirectory(std::span<const std::uint64_t> words) {
  const std::size_t n = words.size();
  super_.resize(n / 512 + 1);
  sub_.resize(n / 8 + 1);
  std::uint64_t total = 0;
  std::uint64_t super_base = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if ((i & 511) == 0) {
      super_base = total;
      super_[i >> 9] = total;
    }
    if ((i & 7) == 0) sub_[i >> 3] = static_cast<std::uint16_t>(total - super_base);
    total += static_cast<std::uint64_t>(std::popcount(words[i]));
  }
  // Entries for index == n (a rank query one past the end).
  if ((n & 511) == 0) {
    super_base = total;
    super_[n >> 9] = total;
  }
  if ((n & 7) == 0) sub_[n >> 3] = static_cast<std::uint16_t>(total - super_base);
  total_ = total;
}

Tree::Tree() {
  auto root = std::make_shared<std::vector<std::uint64_t>>(1, 0);
  all_words_ = *root;
  keeper_ = std::move(root);
  index({}, 0);
}

Tree Tree::from_levels(int depth, bool has_payload, std::vector<std::uint64_t> words,
                       const std::string& source, std::uint64_t file_offset) {
  auto owned = std::make_shared<std::vector<std::uint64_t>>(std::move(words));
  Tree tree = view_levels(depth, has_payload, *owned, owned, source, file_offset);
  tree.mapped_ = false;
  return tree;
}

Tree Tree::view_levels(int depth, bool has_payload, std::span<const std::uint64_t> words,
                       std::shared_ptr<const void> keeper, const std::string& source,
                       std::uint64_t file_offset) {
  if (depth < kMinDepth || depth > kMaxDepth)
    throw InvalidArgument("depth " + std::to_string(depth) + " is outside 1..10");
  Tree tree;
  tree.depth_ = depth;
  tree.has_payload_ = has_payload;
  tree.nbits_ = has_payload ? 1 : 0;
  tree.keeper_ = std::move(keeper);
  tree.all_words_ = words;
  tree.mapped_ = true;
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
      throw FormatError(source, file_offset + 8 * all_words_.size(),
                        "level " + std::to_string(level) + " needs " + std::to_string(blocks) +
                            " blocks of " + std::to_string(8 * per_block) + " bytes but only " +
                            std::to_string(available) + " remain (truncated file)");
    }
    occupancy_[level] = all_words_.subspan(at, blocks);
    at += blocks;
    if (has_payload_) {
      payload_[level] = all_words_.subspan(at, blocks);
      at += blocks;
    } else {
      payload_[level] = {};
    }
    rank_[level] = RankDirectory(occupancy_[level]);
    counts_[level] = rank_[level].total();
    if (level > 0) {
      for (std::size_t i = 0; i < occupancy_[level].size(); ++i) {
        if (occupancy_[level][i] == 0) {
          const std::uint64_t word_offset = (occupancy_[level].data() - all_words_.data()) + i;
          throw FormatError(source, file_offset + 8 * word_offset,
                            "level " + std::to_string(level) + " block " + std::to_string(i) +
                                " is empty although its parent bit is set");
        }
      }
    }
    blocks = counts_[level];
  }
  if (at != all_words_.size()) {
    throw FormatError(source, file_offset + 8 * at,
                      std::to_string(8 * (all_words_.size() - at)) +
                          " bytes follow the last level that no level accounts for");
  }
  for (int level = depth_; level < kMaxDepth; ++level) {
    occupancy_[level] = {};
    payload_[level] = {};
    rank_[level] = RankDirectory();
    counts_[level] = 0;
  }
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
    throw InvalidArgument("voxel payloads: " + std::to_string(payloads.size()) + " values for " +
                          std::to_string(voxel_count()) + " voxels");
  voxel_payloads_ = std::move(payloads);
}

std::vector<Key> Tree::keys() const {
  std::vector<Key> out;
  out.reserve(voxel_count());
  for_each_voxel([&](const Voxel& v) { out.push_back(encode(v)); });
  return out;
}

Tree Tree::level_of_detail(int depth) const {
  if (depth < kMinDepth || depth > depth_)
    throw InvalidArgument("level of detail: depth " + std::to_string(depth) + " is outside 1.." +
                          std::to_string(depth_));
  if (depth == depth_) return *this;
  const auto& last = has_payload_ ? payload_[depth - 1] : occupancy_[depth - 1];
  const std::size_t end = static_cast<std::size_t>(last.data() + last.size() - all_words_.data());
  Tree coarse = view_levels(depth, has_payload_, all_words_.first(end), keeper_);
  coarse.mapped_ = mapped_;
  coarse.nbits_ = nbits_;
  coarse.georef_ = georef_;
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
  return Quantizer::toolkit(georef_.bbox, depth_);
}

VOLA_INLINE_NAMESPACE_END
}  // namespace vola
