// Open addressing from a packed 4x4x4-block key to a dense index (0, 1, 2, ... in
// insertion order), the one hash structure of the occupancy map: the per-scan masks and
// the map's blocks both keep their payload in plain vectors indexed by it. A voxel costs
// no probe of its own: callers look a block up once and then set bits in its word.
#pragma once

#include <algorithm>
#include <cstdint>
#include <vector>

namespace vola::map::detail {

class BlockIndex {
 public:
  // Never a packed block key (those use 57 bits).
  static constexpr std::uint64_t kEmpty = ~std::uint64_t{0};

  BlockIndex() { reset(64); }

  // The index of `key`; a new key gets size() (and `added` is set).
  std::uint32_t find_or_add(std::uint64_t key, bool& added) {
    if ((size_ + 1) * 4 > keys_.size() * 3) grow();  // load factor <= 3/4
    added = false;
    const std::size_t mask = keys_.size() - 1;
    for (std::size_t s = hash(key) & mask;; s = (s + 1) & mask) {
      if (keys_[s] == key) return values_[s];
      if (keys_[s] == kEmpty) {
        keys_[s] = key;
        values_[s] = static_cast<std::uint32_t>(size_);
        ++size_;
        added = true;
        return values_[s];
      }
    }
  }
  // The index of `key`, or -1 when absent.
  std::int64_t find(std::uint64_t key) const noexcept {
    const std::size_t mask = keys_.size() - 1;
    for (std::size_t s = hash(key) & mask;; s = (s + 1) & mask) {
      if (keys_[s] == key) return values_[s];
      if (keys_[s] == kEmpty) return -1;
    }
  }
  std::size_t size() const noexcept { return size_; }
  // Empties it, keeping the table's capacity for the next scan.
  void clear() noexcept {
    if (size_ == 0) return;
    std::fill(keys_.begin(), keys_.end(), kEmpty);
    size_ = 0;
  }
  std::size_t memory_bytes() const noexcept { return keys_.capacity() * (sizeof(std::uint64_t) + sizeof(std::uint32_t)); }

 private:
  // splitmix64's finalizer: packed keys differ in a few middle bits only.
  static std::size_t hash(std::uint64_t x) noexcept {
    x ^= x >> 30;
    x *= 0xbf58476d1ce4e5b9ull;
    x ^= x >> 27;
    x *= 0x94d049bb133111ebull;
    x ^= x >> 31;
    return static_cast<std::size_t>(x);
  }
  void reset(std::size_t slots) {
    keys_.assign(slots, kEmpty);
    values_.assign(slots, 0);
  }
  void grow() {
    std::vector<std::uint64_t> keys = std::move(keys_);
    std::vector<std::uint32_t> values = std::move(values_);
    reset(keys.size() * 2);
    const std::size_t mask = keys_.size() - 1;
    for (std::size_t i = 0; i < keys.size(); ++i) {
      if (keys[i] == kEmpty) continue;
      std::size_t s = hash(keys[i]) & mask;
      while (keys_[s] != kEmpty) s = (s + 1) & mask;
      keys_[s] = keys[i];
      values_[s] = values[i];
    }
  }

  std::vector<std::uint64_t> keys_;
  std::vector<std::uint32_t> values_;
  std::size_t size_ = 0;
};

}  // namespace vola::map::detail
