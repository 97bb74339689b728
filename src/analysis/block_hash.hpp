// An open-addressing hash map from packed block coordinates to one 64-bit value: the
// occupancy word of a brick (morphology) or a block index (components). Linear
// probing, power-of-two capacity, grown at 50% load.
#pragma once

#include <bit>
#include <cstdint>
#include <vector>

namespace vola::analysis::detail {

// Block coordinates are below 4^10 / 4 = 2^18 per axis: 18 bits each.
inline std::uint64_t pack_block(std::int64_t bx, std::int64_t by, std::int64_t bz) noexcept {
  return static_cast<std::uint64_t>(bx) | (static_cast<std::uint64_t>(by) << 18) |
         (static_cast<std::uint64_t>(bz) << 36);
}
inline std::uint32_t block_x(std::uint64_t packed) noexcept { return packed & 0x3FFFFu; }
inline std::uint32_t block_y(std::uint64_t packed) noexcept { return (packed >> 18) & 0x3FFFFu; }
inline std::uint32_t block_z(std::uint64_t packed) noexcept { return (packed >> 36) & 0x3FFFFu; }

class BlockHash {
 public:
  static constexpr std::uint64_t kEmpty = ~std::uint64_t{0};

  explicit BlockHash(std::size_t expected = 0) { rehash(capacity_for(expected)); }

  // The value slot of `key`, inserted with value 0 if missing.
  std::uint64_t& at(std::uint64_t key) {
    if (2 * (size_ + 1) > keys_.size()) rehash(keys_.size() * 2);
    std::size_t i = slot(key);
    while (keys_[i] != kEmpty && keys_[i] != key) i = (i + 1) & mask_;
    if (keys_[i] == kEmpty) {
      keys_[i] = key;
      values_[i] = 0;
      ++size_;
    }
    return values_[i];
  }
  const std::uint64_t* find(std::uint64_t key) const noexcept {
    std::size_t i = slot(key);
    while (keys_[i] != kEmpty) {
      if (keys_[i] == key) return &values_[i];
      i = (i + 1) & mask_;
    }
    return nullptr;
  }
  std::size_t size() const noexcept { return size_; }
  // f(key, value) for every entry, in slot order.
  template <class F>
  void for_each(F&& f) const {
    for (std::size_t i = 0; i < keys_.size(); ++i)
      if (keys_[i] != kEmpty) f(keys_[i], values_[i]);
  }
  std::size_t memory_bytes() const noexcept { return keys_.capacity() * 16; }

 private:
  static std::size_t capacity_for(std::size_t n) {
    std::size_t c = 16;
    while (c < 2 * n) c *= 2;
    return c;
  }
  std::size_t slot(std::uint64_t key) const noexcept {
    return static_cast<std::size_t>((key * 0x9E3779B97F4A7C15ull) >> shift_);
  }
  void rehash(std::size_t capacity) {
    std::vector<std::uint64_t> old_keys(capacity, kEmpty), old_values(capacity, 0);
    old_keys.swap(keys_);
    old_values.swap(values_);
    mask_ = capacity - 1;
    shift_ = 64 - std::countr_zero(capacity);
    size_ = 0;
    for (std::size_t i = 0; i < old_keys.size(); ++i)
      if (old_keys[i] != kEmpty) at(old_keys[i]) = old_values[i];
  }

  std::vector<std::uint64_t> keys_, values_;
  std::size_t mask_ = 0;
  int shift_ = 64;
  std::size_t size_ = 0;
};

}  // namespace vola::analysis::detail
